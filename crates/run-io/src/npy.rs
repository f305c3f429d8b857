//! Rows of `f64` streamed to a NumPy `.npy` file (format 1.0, little-endian `<f8`, C order,
//! shape `(rows, cols)`), so that a run can write millions to billions of positions as it goes,
//! without holding them, into a file `numpy.load(path, mmap_mode="r")` maps directly.
//!
//! The header has a fixed size of [`HEADER_BYTES`] (a multiple of 64, as the format asks), so
//! the row count in it can be rewritten in place: [`NpyWriter::sync`] flushes the rows and
//! records their number. A file whose writer was killed holds a valid array of the rows counted
//! at the last sync, followed by rows nobody counted (NumPy reads the counted ones);
//! [`NpyWriter::resume`] cuts such a file back to a given number of rows and appends from
//! there. Unlike the other outputs this file is not written atomically: it is the run's
//! arrival log, and a checkpoint refers to a prefix of it.

use std::fs::{File, OpenOptions};
use std::io::{self, BufReader, BufWriter, Read, Seek, SeekFrom, Write};
use std::path::{Path, PathBuf};

/// Bytes before the first row: magic, version, header length and the padded header text.
pub const HEADER_BYTES: u64 = 128;
const MAGIC: &[u8; 6] = b"\x93NUMPY";

/// Why an `.npy` file cannot be read as rows of `f64`.
#[derive(Debug, thiserror::Error)]
pub enum NpyError {
    /// Reading or writing failed.
    #[error("{path}: {source}")]
    Io {
        /// The file.
        path: PathBuf,
        /// The cause.
        source: io::Error,
    },
    /// Not an `.npy` file of this layout, or fewer rows than asked for.
    #[error("{path}: {why}")]
    Format {
        /// The file.
        path: PathBuf,
        /// What is wrong.
        why: String,
    },
}

fn io_error(path: &Path) -> impl FnOnce(io::Error) -> NpyError + '_ {
    move |source| NpyError::Io {
        path: path.to_path_buf(),
        source,
    }
}

fn format_error(path: &Path, why: impl Into<String>) -> NpyError {
    NpyError::Format {
        path: path.to_path_buf(),
        why: why.into(),
    }
}

/// What an `.npy` file of this module holds: rows of `cols` `f64` (a `(rows, cols)` array
/// of `<f8`), or one `i64` per row (a `(rows,)` array of `<i8`: indices such as DLA's parents).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
enum Elements {
    Reals(usize),
    Ints,
}

impl Elements {
    /// Eight-byte values per row.
    fn cols(self) -> usize {
        match self {
            Elements::Reals(c) => c,
            Elements::Ints => 1,
        }
    }

    fn describe(self) -> String {
        match self {
            Elements::Reals(c) => format!("{c} columns of f64"),
            Elements::Ints => "one column of i64".into(),
        }
    }
}

/// The [`HEADER_BYTES`] bytes of an array of `rows` rows of `what`.
fn header(rows: u64, what: Elements) -> Vec<u8> {
    match what {
        Elements::Reals(cols) => header_bytes("<f8", rows, Some(cols)),
        Elements::Ints => header_bytes("<i8", rows, None),
    }
}

/// The [`HEADER_BYTES`] bytes of a C-order array of NumPy type `descr` (`<f8`, `<i8`) with
/// shape `(rows, cols)`, or `(rows,)` without `cols`.
pub(crate) fn header_bytes(descr: &str, rows: u64, cols: Option<usize>) -> Vec<u8> {
    let shape = match cols {
        Some(c) => format!("({rows}, {c})"),
        None => format!("({rows},)"),
    };
    let text = format!("{{'descr': '{descr}', 'fortran_order': False, 'shape': {shape}, }}");
    let mut h = Vec::with_capacity(HEADER_BYTES as usize);
    h.extend_from_slice(MAGIC);
    h.extend_from_slice(&[1, 0]);
    let len = HEADER_BYTES as usize - 10;
    h.extend_from_slice(&(len as u16).to_le_bytes());
    h.extend_from_slice(text.as_bytes());
    h.resize(HEADER_BYTES as usize - 1, b' ');
    h.push(b'\n');
    h
}

/// Reads the header of `file`: the rows and what each holds.
fn read_header(file: &mut File, path: &Path) -> Result<(u64, Elements), NpyError> {
    let mut h = [0u8; HEADER_BYTES as usize];
    file.seek(SeekFrom::Start(0)).map_err(io_error(path))?;
    file.read_exact(&mut h)
        .map_err(|_| format_error(path, "too short for an .npy header"))?;
    if &h[..6] != MAGIC || h[6] != 1 || u16::from_le_bytes([h[8], h[9]]) != 118 {
        return Err(format_error(
            path,
            "not an .npy file written by aggsim (format 1.0, 128-byte header)",
        ));
    }
    let text =
        std::str::from_utf8(&h[10..]).map_err(|_| format_error(path, "header is not text"))?;
    let ints = text.contains("'descr': '<i8'");
    if !(ints || text.contains("'descr': '<f8'")) || !text.contains("'fortran_order': False") {
        return Err(format_error(
            path,
            "not a C-ordered array of little-endian f64 or i64",
        ));
    }
    let shape = text
        .split("'shape': (")
        .nth(1)
        .and_then(|s| s.split(')').next())
        .ok_or_else(|| format_error(path, "header has no shape"))?;
    let dims: Vec<&str> = shape
        .split(',')
        .map(str::trim)
        .filter(|s| !s.is_empty())
        .collect();
    let (rows, cols) = match (dims.as_slice(), ints) {
        ([r, c], false) => match (r.parse::<u64>(), c.parse::<usize>()) {
            (Ok(r), Ok(c)) if c > 0 => (r, c),
            _ => return Err(format_error(path, format!("bad shape ({shape})"))),
        },
        ([r], true) => match r.parse::<u64>() {
            Ok(r) => (r, 1),
            _ => return Err(format_error(path, format!("bad shape ({shape})"))),
        },
        (_, false) => {
            return Err(format_error(
                path,
                format!("shape ({shape}) is not two-dimensional"),
            ));
        }
        (_, true) => {
            return Err(format_error(
                path,
                format!("shape ({shape}) of i64 is not one-dimensional"),
            ));
        }
    };
    // A row is sized by the column count, so that is bounded before anyone allocates one;
    // the row count sizes nothing (rows are read one at a time, and a file shorter than its
    // count is an error when the reader gets there).
    if cols > MAX_COLS {
        return Err(format_error(
            path,
            format!("shape ({shape}) has more than {MAX_COLS} columns"),
        ));
    }
    Ok((
        rows,
        if ints {
            Elements::Ints
        } else {
            Elements::Reals(cols)
        },
    ))
}

/// Most columns an `.npy` file this reader opens may have (aggsim writes at most a few).
pub const MAX_COLS: usize = 1 << 16;

/// Appends rows of `cols` `f64` to an `.npy` file (see the module doc).
#[derive(Debug)]
pub struct NpyWriter {
    path: PathBuf,
    out: BufWriter<File>,
    what: Elements,
    rows: u64,
}

impl NpyWriter {
    /// A new file at `path` (replacing any), holding no rows yet.
    ///
    /// # Errors
    /// The file cannot be created or written.
    pub fn create(path: impl AsRef<Path>, cols: usize) -> Result<Self, NpyError> {
        Self::create_of(path.as_ref(), Elements::Reals(cols))
    }

    /// A new file at `path` (replacing any) of `i64` values, one per row (a 1-D array),
    /// holding none yet: append with [`push_int`](Self::push_int).
    ///
    /// # Errors
    /// The file cannot be created or written.
    pub fn create_ints(path: impl AsRef<Path>) -> Result<Self, NpyError> {
        Self::create_of(path.as_ref(), Elements::Ints)
    }

    fn create_of(path: &Path, what: Elements) -> Result<Self, NpyError> {
        let path = path.to_path_buf();
        let mut file = File::create(&path).map_err(io_error(&path))?;
        file.write_all(&header(0, what)).map_err(io_error(&path))?;
        Ok(NpyWriter {
            out: BufWriter::with_capacity(1 << 20, file),
            path,
            what,
            rows: 0,
        })
    }

    /// The file at `path`, cut back to its first `rows` rows (which it must hold), to append
    /// after them.
    ///
    /// # Errors
    /// [`NpyError::Format`] if the file is not an array of `cols` columns holding at least
    /// `rows` rows (counted or not); I/O errors.
    pub fn resume(path: impl AsRef<Path>, cols: usize, rows: u64) -> Result<Self, NpyError> {
        Self::resume_of(path.as_ref(), Elements::Reals(cols), rows)
    }

    /// [`resume`](Self::resume) of a file of `i64` values ([`create_ints`](Self::create_ints)).
    ///
    /// # Errors
    /// As for [`resume`](Self::resume).
    pub fn resume_ints(path: impl AsRef<Path>, rows: u64) -> Result<Self, NpyError> {
        Self::resume_of(path.as_ref(), Elements::Ints, rows)
    }

    fn resume_of(path: &Path, what: Elements, rows: u64) -> Result<Self, NpyError> {
        let path = path.to_path_buf();
        let cols = what.cols();
        let mut file = OpenOptions::new()
            .read(true)
            .write(true)
            .open(&path)
            .map_err(io_error(&path))?;
        let (_, found) = read_header(&mut file, &path)?;
        if found != what {
            return Err(format_error(
                &path,
                format!("{}, not {}", found.describe(), what.describe()),
            ));
        }
        let end = HEADER_BYTES + rows * 8 * cols as u64;
        let len = file.metadata().map_err(io_error(&path))?.len();
        if len < end {
            return Err(format_error(
                &path,
                format!(
                    "holds {} rows, fewer than {rows}",
                    (len - HEADER_BYTES.min(len)) / (8 * cols as u64)
                ),
            ));
        }
        file.set_len(end).map_err(io_error(&path))?;
        file.seek(SeekFrom::Start(0)).map_err(io_error(&path))?;
        file.write_all(&header(rows, what))
            .map_err(io_error(&path))?;
        file.seek(SeekFrom::Start(end)).map_err(io_error(&path))?;
        Ok(NpyWriter {
            out: BufWriter::with_capacity(1 << 20, file),
            path,
            what,
            rows,
        })
    }

    /// Appends one value to a file of `i64` ([`create_ints`](Self::create_ints)).
    ///
    /// # Errors
    /// Writing failed.
    pub fn push_int(&mut self, value: i64) -> Result<(), NpyError> {
        debug_assert_eq!(self.what, Elements::Ints);
        self.out
            .write_all(&value.to_le_bytes())
            .map_err(io_error(&self.path))?;
        self.rows += 1;
        Ok(())
    }

    /// Appends one row (`row.len()` must be the column count).
    ///
    /// # Errors
    /// Writing failed.
    pub fn push(&mut self, row: &[f64]) -> Result<(), NpyError> {
        debug_assert_eq!(self.what, Elements::Reals(row.len()));
        for x in row {
            self.out
                .write_all(&x.to_le_bytes())
                .map_err(io_error(&self.path))?;
        }
        self.rows += 1;
        Ok(())
    }

    /// Rows written.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// The file.
    pub fn path(&self) -> &Path {
        &self.path
    }

    /// Flushes the rows, records their number in the header and syncs the file to disk: after
    /// this the file is a complete array of [`rows`](Self::rows) rows.
    ///
    /// # Errors
    /// Writing failed.
    pub fn sync(&mut self) -> Result<(), NpyError> {
        let rows = self.rows;
        let what = self.what;
        let path = self.path.clone();
        self.out.flush().map_err(io_error(&path))?;
        let file = self.out.get_mut();
        let end = file.stream_position().map_err(io_error(&path))?;
        file.seek(SeekFrom::Start(0)).map_err(io_error(&path))?;
        file.write_all(&header(rows, what))
            .map_err(io_error(&path))?;
        file.seek(SeekFrom::Start(end)).map_err(io_error(&path))?;
        file.sync_data().map_err(io_error(&path))?;
        Ok(())
    }
}

/// Reads the rows of an `.npy` file of `f64` one by one, without loading the file.
#[derive(Debug)]
pub struct NpyReader {
    path: PathBuf,
    input: BufReader<File>,
    what: Elements,
    rows: u64,
    read: u64,
}

impl NpyReader {
    /// Opens `path` and reads its header.
    ///
    /// # Errors
    /// [`NpyError::Format`] if it is not an array of `f64` written by [`NpyWriter`].
    pub fn open(path: impl AsRef<Path>) -> Result<Self, NpyError> {
        let r = Self::open_any(path.as_ref())?;
        match r.what {
            Elements::Reals(_) => Ok(r),
            Elements::Ints => Err(format_error(&r.path, "an array of i64, not of f64")),
        }
    }

    /// Opens a file of `i64` values, one per row ([`NpyWriter::create_ints`]); read them with
    /// [`next_int`](Self::next_int).
    ///
    /// # Errors
    /// [`NpyError::Format`] if it is not a 1-D array of `i64` written by [`NpyWriter`].
    pub fn open_ints(path: impl AsRef<Path>) -> Result<Self, NpyError> {
        let r = Self::open_any(path.as_ref())?;
        match r.what {
            Elements::Ints => Ok(r),
            Elements::Reals(_) => Err(format_error(&r.path, "an array of f64, not of i64")),
        }
    }

    fn open_any(path: &Path) -> Result<Self, NpyError> {
        let path = path.to_path_buf();
        let mut file = File::open(&path).map_err(io_error(&path))?;
        let (rows, what) = read_header(&mut file, &path)?;
        Ok(NpyReader {
            input: BufReader::with_capacity(1 << 20, file),
            path,
            what,
            rows,
            read: 0,
        })
    }

    /// Columns per row (1 for a file of `i64`).
    pub fn cols(&self) -> usize {
        self.what.cols()
    }

    /// The next of the counted values of a file of `i64` ([`open_ints`](Self::open_ints)),
    /// `None` after the last.
    ///
    /// # Errors
    /// [`NpyError::Format`] if the file ends before its counted rows.
    pub fn next_int(&mut self) -> Result<Option<i64>, NpyError> {
        debug_assert_eq!(self.what, Elements::Ints);
        let mut x = [0.0];
        Ok(self.next_row(&mut x)?.then(|| x[0].to_bits() as i64))
    }

    /// Rows the header counts.
    pub fn rows(&self) -> u64 {
        self.rows
    }

    /// Reads the next row into `row` (of the column count); `false` after the counted rows.
    /// Rows after them (written after the last [`NpyWriter::sync`]) are reachable with
    /// [`read_beyond`](Self::read_beyond).
    ///
    /// # Errors
    /// [`NpyError::Format`] if the file ends before its counted rows.
    pub fn next_row(&mut self, row: &mut [f64]) -> Result<bool, NpyError> {
        if self.read >= self.rows {
            return Ok(false);
        }
        self.read_beyond(row)
    }

    /// Reads the next row even past the counted ones; `false` at the end of the file.
    ///
    /// # Errors
    /// [`NpyError::Format`] if the file ends inside a row or inside the counted rows.
    pub fn read_beyond(&mut self, row: &mut [f64]) -> Result<bool, NpyError> {
        debug_assert_eq!(row.len(), self.what.cols());
        let mut b = [0u8; 8];
        for (k, x) in row.iter_mut().enumerate() {
            match self.input.read_exact(&mut b) {
                Ok(()) => *x = f64::from_le_bytes(b),
                Err(e)
                    if e.kind() == io::ErrorKind::UnexpectedEof
                        && k == 0
                        && self.read >= self.rows =>
                {
                    return Ok(false);
                }
                Err(e) if e.kind() == io::ErrorKind::UnexpectedEof => {
                    return Err(format_error(
                        &self.path,
                        format!(
                            "ends inside row {} (the header counts {})",
                            self.read, self.rows
                        ),
                    ));
                }
                Err(e) => return Err(io_error(&self.path)(e)),
            }
        }
        self.read += 1;
        Ok(true)
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn rows_round_trip_and_the_header_counts_the_synced_rows() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.npy");
        let mut w = NpyWriter::create(&path, 3).unwrap();
        for i in 0..1000 {
            let x = f64::from(i);
            w.push(&[x, -x, x * 1e-300]).unwrap();
        }
        w.sync().unwrap();
        // Rows after the last sync: in the file, not counted.
        w.push(&[1.0, 2.0, 3.0]).unwrap();
        drop(w);
        let bytes = std::fs::read(&path).unwrap();
        assert_eq!(bytes.len() as u64, HEADER_BYTES + 1001 * 24);
        assert_eq!(HEADER_BYTES % 64, 0);
        let text = String::from_utf8_lossy(&bytes[10..HEADER_BYTES as usize]);
        assert!(text.contains("'shape': (1000, 3)"), "{text}");
        assert!(text.ends_with('\n'));
        let mut r = NpyReader::open(&path).unwrap();
        assert_eq!((r.rows(), r.cols()), (1000, 3));
        let mut row = [0.0; 3];
        let mut i = 0;
        while r.next_row(&mut row).unwrap() {
            let x = f64::from(i);
            assert_eq!(row, [x, -x, x * 1e-300]);
            i += 1;
        }
        assert_eq!(i, 1000);
        assert!(r.read_beyond(&mut row).unwrap());
        assert_eq!(row, [1.0, 2.0, 3.0]);
        assert!(!r.read_beyond(&mut row).unwrap());
    }

    #[test]
    fn resume_cuts_back_and_appends() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("p.npy");
        let mut w = NpyWriter::create(&path, 2).unwrap();
        for i in 0..10 {
            w.push(&[f64::from(i), 0.5]).unwrap();
        }
        w.sync().unwrap();
        drop(w);
        let mut w = NpyWriter::resume(&path, 2, 4).unwrap();
        w.push(&[40.0, 0.5]).unwrap();
        w.sync().unwrap();
        let mut r = NpyReader::open(&path).unwrap();
        let mut all = Vec::new();
        let mut row = [0.0; 2];
        while r.next_row(&mut row).unwrap() {
            all.push(row[0]);
        }
        assert_eq!(all, vec![0.0, 1.0, 2.0, 3.0, 40.0]);
        assert!(matches!(
            NpyWriter::resume(&path, 2, 6),
            Err(NpyError::Format { .. })
        ));
        assert!(matches!(
            NpyWriter::resume(&path, 3, 1),
            Err(NpyError::Format { .. })
        ));
    }

    #[test]
    fn ints_round_trip_resume_and_are_told_from_reals() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("positions_parent.npy");
        let mut w = NpyWriter::create_ints(&path).unwrap();
        for i in -1..9 {
            w.push_int(i * 1_000_000_007).unwrap();
        }
        w.sync().unwrap();
        drop(w);
        let bytes = std::fs::read(&path).unwrap();
        let text = String::from_utf8_lossy(&bytes[10..HEADER_BYTES as usize]);
        assert!(
            text.contains("'descr': '<i8'") && text.contains("'shape': (10,)"),
            "{text}"
        );
        let mut w = NpyWriter::resume_ints(&path, 4).unwrap();
        w.push_int(i64::MIN).unwrap();
        w.sync().unwrap();
        let mut r = NpyReader::open_ints(&path).unwrap();
        let mut all = Vec::new();
        while let Some(x) = r.next_int().unwrap() {
            all.push(x);
        }
        assert_eq!(
            all,
            vec![-1_000_000_007, 0, 1_000_000_007, 2_000_000_014, i64::MIN]
        );
        assert!(matches!(
            NpyReader::open(&path),
            Err(NpyError::Format { .. })
        ));
        assert!(matches!(
            NpyWriter::resume(&path, 1, 1),
            Err(NpyError::Format { .. })
        ));
        let reals = dir.path().join("p.npy");
        NpyWriter::create(&reals, 1).unwrap().sync().unwrap();
        assert!(matches!(
            NpyReader::open_ints(&reals),
            Err(NpyError::Format { .. })
        ));
        assert!(matches!(
            NpyWriter::resume_ints(&reals, 0),
            Err(NpyError::Format { .. })
        ));
    }

    #[test]
    fn other_files_and_truncation_are_format_errors() {
        let dir = tempfile::tempdir().unwrap();
        let path = dir.path().join("x.npy");
        std::fs::write(&path, b"hello").unwrap();
        assert!(matches!(
            NpyReader::open(&path),
            Err(NpyError::Format { .. })
        ));
        let mut w = NpyWriter::create(&path, 2).unwrap();
        w.push(&[1.0, 2.0]).unwrap();
        w.push(&[3.0, 4.0]).unwrap();
        w.sync().unwrap();
        drop(w);
        let f = OpenOptions::new().write(true).open(&path).unwrap();
        f.set_len(HEADER_BYTES + 24).unwrap();
        let mut r = NpyReader::open(&path).unwrap();
        let mut row = [0.0; 2];
        assert!(r.next_row(&mut row).unwrap());
        assert!(matches!(r.next_row(&mut row), Err(NpyError::Format { .. })));
    }
}
