//! CSV tables with a header line (time series, size distributions, positions), written
//! atomically through the `csv` crate (which quotes fields when needed).

use super::atomic::AtomicFile;
use std::fmt::Write as _;
use std::io;
use std::path::Path;

/// A CSV file being written: the header first, then rows with the same number of fields.
/// Nothing appears at the path until [`CsvWriter::finish`].
#[derive(Debug)]
pub struct CsvWriter {
    inner: csv::Writer<AtomicFile>,
    columns: usize,
    field: String,
}

impl CsvWriter {
    /// Create `path` with the given header line.
    pub fn create(path: impl AsRef<Path>, header: &[&str]) -> io::Result<Self> {
        if header.is_empty() {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                "CSV header has no columns",
            ));
        }
        let mut inner = csv::Writer::from_writer(AtomicFile::create(path)?);
        inner.write_record(header).map_err(io::Error::other)?;
        Ok(CsvWriter {
            inner,
            columns: header.len(),
            field: String::new(),
        })
    }

    /// Write one row; it must have as many fields as the header. Floats use Rust's shortest
    /// round-trip formatting (switching to exponent notation for very large or small values), so
    /// reading them back gives the same `f64`.
    pub fn row(&mut self, fields: &[&dyn CsvField]) -> io::Result<()> {
        if fields.len() != self.columns {
            return Err(io::Error::new(
                io::ErrorKind::InvalidInput,
                format!(
                    "CSV row has {} fields, the header has {}",
                    fields.len(),
                    self.columns
                ),
            ));
        }
        for f in fields {
            self.field.clear();
            f.write_field(&mut self.field);
            self.inner
                .write_field(&self.field)
                .map_err(io::Error::other)?;
        }
        self.inner
            .write_record(None::<&[u8]>)
            .map_err(io::Error::other)
    }

    /// Flush and move the file into place.
    pub fn finish(self) -> io::Result<()> {
        let file = self
            .inner
            .into_inner()
            .map_err(|e| io::Error::other(e.to_string()))?;
        file.commit()
    }
}

/// A value that can be a CSV field.
pub trait CsvField {
    /// Append the field's text to `out`.
    fn write_field(&self, out: &mut String);
}

macro_rules! display_field {
    ($($t:ty),*) => {$(
        impl CsvField for $t {
            fn write_field(&self, out: &mut String) {
                write!(out, "{self}").expect("writing to a String cannot fail");
            }
        }
    )*};
}
display_field!(
    u8, u16, u32, u64, u128, usize, i8, i16, i32, i64, i128, isize, bool, str, String
);

macro_rules! float_field {
    ($($t:ty),*) => {$(
        impl CsvField for $t {
            fn write_field(&self, out: &mut String) {
                // Debug is Display's shortest round-trip digits, but with exponents for
                // extreme magnitudes (1e-300 rather than 300 zeros).
                write!(out, "{self:?}").expect("writing to a String cannot fail");
            }
        }
    )*};
}
float_field!(f32, f64);

impl<T: CsvField + ?Sized> CsvField for &T {
    fn write_field(&self, out: &mut String) {
        (**self).write_field(out);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn header_rows_and_quoting() {
        let dir = tempfile::tempdir().unwrap();
        let p = dir.path().join("t.csv");
        let mut w = CsvWriter::create(&p, &["sweep", "clusters", "note"]).unwrap();
        w.row(&[&1, &0.1f64, &"plain"]).unwrap();
        w.row(&[&2, &1e-300f64, &"with, comma"]).unwrap();
        assert!(w.row(&[&3, &4]).is_err());
        assert!(!p.exists());
        w.finish().unwrap();
        let text = std::fs::read_to_string(&p).unwrap();
        assert_eq!(
            text,
            "sweep,clusters,note\n1,0.1,plain\n2,1e-300,\"with, comma\"\n"
        );
    }
}
