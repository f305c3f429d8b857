//! Point sets (particles, animats) in the formats that field tools read, chosen by every model's
//! `--positions`:
//!
//! | format | files | read by |
//! |---|---|---|
//! | `csv` | `STEM.csv`: the coordinates, then one column per attribute | pandas, R, spreadsheets |
//! | `npy` | `STEM.npy`: `(N, D)`, float64 off lattice, int64 for lattice sites; `STEM_<attribute>.npy`: int64 `(N,)` each | `numpy.load` (memory-mapped) |
//! | `vtk` | `STEM.vtk`: legacy VTK, binary `UNSTRUCTURED_GRID`, one vertex cell per point, the attributes as point scalars | ParaView, VisIt, pyvista, meshio |
//! | `xyz` | `STEM.xyz`: extended XYZ (count, a `Properties=` comment line, one line per point) | OVITO, VMD, ASE |
//!
//! Lattice sites are integers in every format but VTK (whose points are float64 for every
//! viewer): they reach the writer as `i64` ([`Coords::Int`]), so a site beyond 2^53 keeps
//! its value.
//!
//! Points come from a visitor the writer may call more than once (VTK stores each attribute in
//! its own section after all coordinates), so a caller that streams its points from disk never
//! holds them in memory. Every file is written atomically.

use super::atomic::AtomicFile;
use super::{CsvField, CsvWriter, OutputError};
use std::io::{self, BufWriter, Write};
use std::path::Path;

mod vtk;

/// A positions file format (`--positions`).
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum PointFormat {
    /// CSV with a header line.
    Csv,
    /// NumPy `.npy`: coordinates `(N, D)` (float64, int64 for lattice sites), each attribute
    /// int64 `(N,)` in its own file.
    Npy,
    /// Legacy VTK (binary `UNSTRUCTURED_GRID` with vertex cells and point scalars) for
    /// ParaView, VisIt, pyvista and meshio.
    Vtk,
    /// Extended XYZ for OVITO, VMD and ASE.
    Xyz,
}

impl PointFormat {
    /// The file extension.
    pub fn extension(self) -> &'static str {
        match self {
            PointFormat::Csv => "csv",
            PointFormat::Npy => "npy",
            PointFormat::Vtk => "vtk",
            PointFormat::Xyz => "xyz",
        }
    }
}

/// `--positions` of the lattice and animat models: a [`PointFormat`] or no file.
#[derive(Debug, Clone, Copy, PartialEq, Eq, serde::Serialize, serde::Deserialize)]
#[cfg_attr(feature = "clap", derive(clap::ValueEnum))]
#[serde(rename_all = "lowercase")]
pub enum Positions {
    /// No positions file.
    None,
    /// CSV with a header line.
    Csv,
    /// NumPy `.npy`: coordinates `(N, D)` (float64, int64 for lattice sites), each attribute
    /// int64 `(N,)` in its own file.
    Npy,
    /// Legacy VTK (binary `UNSTRUCTURED_GRID` with vertex cells and point scalars) for
    /// ParaView, VisIt, pyvista and meshio.
    Vtk,
    /// Extended XYZ for OVITO, VMD and ASE.
    Xyz,
}

impl Positions {
    /// The format to write, if any.
    pub fn format(self) -> Option<PointFormat> {
        match self {
            Positions::None => None,
            Positions::Csv => Some(PointFormat::Csv),
            Positions::Npy => Some(PointFormat::Npy),
            Positions::Vtk => Some(PointFormat::Vtk),
            Positions::Xyz => Some(PointFormat::Xyz),
        }
    }
}

/// The most points legacy VTK holds: its cell list counts `2 N` 32-bit integers.
pub const VTK_MAX_POINTS: u64 = (i32::MAX / 2) as u64;

/// An integer attribute of every point (a cluster id, a species).
#[derive(Debug, Clone, Copy)]
pub struct Attribute<'a> {
    /// Its name: a CSV column, a VTK scalar, the suffix of its `.npy` file.
    pub name: &'a str,
    /// Names of the values `0, 1, ...`, written instead of the numbers in CSV and XYZ (a
    /// species); `None` writes the numbers.
    pub labels: Option<&'a [&'a str]>,
}

/// What a point set holds, apart from the points themselves.
#[derive(Debug, Clone, Copy)]
pub struct PointSet<'a> {
    /// Number of points the visitor yields.
    pub n: u64,
    /// Names of the coordinates (`x`, `y`, `z` or `x1`, ... `xd`); their number is the dimension.
    pub axes: &'a [&'a str],
    /// Whether the coordinates are integers (lattice sites): the visitor then yields
    /// [`Coords::Int`], `.npy` holds int64 and CSV and XYZ write them without a fractional
    /// part; otherwise it yields [`Coords::Float`] and `.npy` holds float64.
    pub integer_coordinates: bool,
    /// The explicit attributes, in the order the visitor yields them.
    pub attributes: &'a [Attribute<'a>],
    /// A name for the point's index (its order: `arrival` for DLA), written as a VTK scalar;
    /// the other formats keep it as the row order.
    pub index: Option<&'a str>,
    /// One line describing the set (VTK title, XYZ comment).
    pub title: &'a str,
    /// The attribute (an index into `attributes`) holding each point's parent, the index of
    /// another point or `-1`: VTK then draws each point with a parent as a line cell from
    /// the parent to it (roots stay vertices), so that ParaView shows the branches; the other
    /// formats keep it as the attribute it is.
    pub parent: Option<usize>,
}

/// One point's coordinates: off-lattice centres or lattice sites.
#[derive(Debug, Clone, Copy)]
pub enum Coords<'a> {
    /// Real coordinates (a set without [`PointSet::integer_coordinates`]).
    Float(&'a [f64]),
    /// Integer coordinates (a set with [`PointSet::integer_coordinates`]).
    Int(&'a [i64]),
}

impl Coords<'_> {
    /// Coordinate `i` as a float (0 past the last axis): VTK's points.
    fn float(&self, i: usize) -> f64 {
        match self {
            Coords::Float(p) => p.get(i).copied().unwrap_or(0.0),
            Coords::Int(p) => p.get(i).map_or(0.0, |&x| x as f64),
        }
    }

    fn is_int(&self) -> bool {
        matches!(self, Coords::Int(_))
    }
}

/// A function that calls its argument with each point in order: coordinates, then attributes.
pub type Visitor<'v> =
    dyn FnMut(&mut dyn FnMut(Coords<'_>, &[i64]) -> io::Result<()>) -> Result<(), OutputError> + 'v;

/// The error of a point whose coordinates are not of the kind `set` declares.
fn kind_error(set: &PointSet<'_>) -> io::Error {
    io::Error::new(
        io::ErrorKind::InvalidData,
        format!(
            "{}: a point's coordinates are not {}",
            set.title,
            if set.integer_coordinates {
                "integers"
            } else {
                "floats"
            }
        ),
    )
}

/// Writes `set` as `dir/STEM.<extension>` (and, for `npy`, one file per attribute); returns the
/// paths written. `visit` yields the points and may be called several times.
pub fn write_points(
    dir: &Path,
    stem: &str,
    format: PointFormat,
    set: &PointSet<'_>,
    visit: &mut Visitor<'_>,
) -> Result<Vec<std::path::PathBuf>, OutputError> {
    let path = dir.join(format!("{stem}.{}", format.extension()));
    let mut written = vec![path.clone()];
    let checked = |count: u64| -> Result<(), OutputError> {
        if count == set.n {
            Ok(())
        } else {
            Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!(
                    "{}: {count} points visited, {} announced",
                    path.display(),
                    set.n
                ),
            )
            .into())
        }
    };
    match format {
        PointFormat::Csv => {
            let header: Vec<&str> = set
                .axes
                .iter()
                .copied()
                .chain(set.attributes.iter().map(|a| a.name))
                .collect();
            let mut w = CsvWriter::create(&path, &header)?;
            let mut count = 0u64;
            visit(&mut |p, attrs| {
                count += 1;
                if p.is_int() != set.integer_coordinates {
                    return Err(kind_error(set));
                }
                let mut fields: Vec<&dyn CsvField> = Vec::with_capacity(header.len());
                match p {
                    Coords::Int(p) => fields.extend(p.iter().map(|x| x as &dyn CsvField)),
                    Coords::Float(p) => fields.extend(p.iter().map(|x| x as &dyn CsvField)),
                }
                let labels: Vec<Option<&str>> = set
                    .attributes
                    .iter()
                    .zip(attrs)
                    .map(|(a, v)| label(a, *v))
                    .collect();
                for (l, v) in labels.iter().zip(attrs) {
                    fields.push(match l {
                        Some(l) => l as &dyn CsvField,
                        None => v as &dyn CsvField,
                    });
                }
                w.row(&fields)
            })?;
            checked(count)?;
            w.finish()?;
        }
        PointFormat::Npy => {
            let dim = set.axes.len();
            let descr = if set.integer_coordinates {
                "<i8"
            } else {
                "<f8"
            };
            let mut coords = NpyFile::create(&path, descr, set.n, Some(dim))?;
            let mut attrs: Vec<NpyFile> = Vec::new();
            for a in set.attributes {
                let p = dir.join(format!("{stem}_{}.npy", a.name));
                attrs.push(NpyFile::create(&p, "<i8", set.n, None)?);
                written.push(p);
            }
            let mut count = 0u64;
            visit(&mut |p, values| {
                count += 1;
                match p {
                    Coords::Int(p) if set.integer_coordinates => {
                        for x in p {
                            coords.out.write_all(&x.to_le_bytes())?;
                        }
                    }
                    Coords::Float(p) if !set.integer_coordinates => {
                        for x in p {
                            coords.out.write_all(&x.to_le_bytes())?;
                        }
                    }
                    _ => return Err(kind_error(set)),
                }
                for (f, v) in attrs.iter_mut().zip(values) {
                    f.out.write_all(&v.to_le_bytes())?;
                }
                Ok(())
            })?;
            checked(count)?;
            coords.commit()?;
            for f in attrs {
                f.commit()?;
            }
        }
        PointFormat::Vtk => vtk::write_vtk(&path, set, visit)?,
        PointFormat::Xyz => {
            let mut f = AtomicFile::create(&path)?;
            let mut count = 0u64;
            {
                let mut b = BufWriter::new(&mut f);
                writeln!(b, "{}", set.n)?;
                // The leading `species` column (the particle type of OVITO and ASE) holds a
                // labelled attribute named `species` if there is one, else `C`.
                let species = set
                    .attributes
                    .iter()
                    .position(|a| a.name == "species" && a.labels.is_some());
                let mut props = String::from("species:S:1:pos:R:3");
                for (k, a) in set.attributes.iter().enumerate() {
                    if Some(k) != species {
                        let kind = if a.labels.is_some() { "S" } else { "I" };
                        props.push_str(&format!(":{}:{kind}:1", a.name));
                    }
                }
                writeln!(
                    b,
                    "Properties={props} Comment=\"{}\"",
                    set.title.replace('"', "'")
                )?;
                visit(&mut |p, values| {
                    count += 1;
                    if p.is_int() != set.integer_coordinates {
                        return Err(kind_error(set));
                    }
                    let element = species
                        .and_then(|k| label(&set.attributes[k], values[k]))
                        .unwrap_or("C");
                    // XYZ holds three coordinates: 0 for the axes a plane lacks.
                    match p {
                        Coords::Int(p) => {
                            let c = |i: usize| p.get(i).copied().unwrap_or(0);
                            write!(b, "{element} {} {} {}", c(0), c(1), c(2))?;
                        }
                        Coords::Float(p) => {
                            let c = |i: usize| p.get(i).copied().unwrap_or(0.0);
                            write!(b, "{element} {} {} {}", c(0), c(1), c(2))?;
                        }
                    }
                    for (k, (a, v)) in set.attributes.iter().zip(values).enumerate() {
                        if Some(k) == species {
                            continue;
                        }
                        match label(a, *v) {
                            Some(l) => write!(b, " {l}")?,
                            None => write!(b, " {v}")?,
                        }
                    }
                    writeln!(b)
                })?;
                b.flush()?;
            }
            checked(count)?;
            f.commit()?;
        }
    }
    Ok(written)
}

fn label<'a>(a: &Attribute<'a>, v: i64) -> Option<&'a str> {
    a.labels
        .and_then(|l| usize::try_from(v).ok().and_then(|i| l.get(i).copied()))
}

/// An `.npy` file of `n` rows written front to back.
struct NpyFile {
    out: BufWriter<AtomicFile>,
}

impl NpyFile {
    fn create(path: &Path, descr: &str, n: u64, cols: Option<usize>) -> io::Result<Self> {
        let mut out = BufWriter::new(AtomicFile::create(path)?);
        out.write_all(&super::npy::header_bytes(descr, n, cols))?;
        Ok(NpyFile { out })
    }

    fn commit(self) -> io::Result<()> {
        self.out
            .into_inner()
            .map_err(|e| io::Error::other(e.to_string()))?
            .commit()
    }
}

#[cfg(test)]
pub(super) mod tests {
    use super::*;

    pub(super) const POINTS: [([f64; 2], [i64; 2]); 3] = [
        ([0.0, 1.5], [0, 7]),
        ([2.0, -1.0], [1, 7]),
        ([3.25, 4.0], [0, 9]),
    ];
    const SPECIES: [&str; 2] = ["rabbit", "fox"];
    const ATTRS: [Attribute<'static>; 2] = [
        Attribute {
            name: "species",
            labels: Some(&SPECIES),
        },
        Attribute {
            name: "cluster",
            labels: None,
        },
    ];

    pub(super) fn set() -> PointSet<'static> {
        PointSet {
            n: 3,
            axes: &["x", "y"],
            integer_coordinates: false,
            attributes: &ATTRS,
            index: Some("arrival"),
            title: "three points",
            parent: None,
        }
    }

    pub(super) fn write(format: PointFormat, dir: &Path) -> Vec<std::path::PathBuf> {
        write_points(dir, "positions", format, &set(), &mut |f| {
            for (p, a) in &POINTS {
                f(Coords::Float(p), a)?;
            }
            Ok(())
        })
        .unwrap()
    }

    #[test]
    fn csv_and_xyz_write_labels_and_numbers() {
        let dir = tempfile::tempdir().unwrap();
        write(PointFormat::Csv, dir.path());
        let csv = std::fs::read_to_string(dir.path().join("positions.csv")).unwrap();
        assert_eq!(
            csv,
            "x,y,species,cluster\n0.0,1.5,rabbit,7\n2.0,-1.0,fox,7\n3.25,4.0,rabbit,9\n"
        );
        write(PointFormat::Xyz, dir.path());
        let xyz = std::fs::read_to_string(dir.path().join("positions.xyz")).unwrap();
        let lines: Vec<&str> = xyz.lines().collect();
        assert_eq!(lines[0], "3");
        assert!(lines[1].starts_with("Properties=species:S:1:pos:R:3:cluster:I:1 "));
        assert_eq!(lines[3], "fox 2 -1 0 7");
        assert_eq!(lines.len(), 5);
    }

    #[test]
    fn npy_files_read_back() {
        let dir = tempfile::tempdir().unwrap();
        let files = write(PointFormat::Npy, dir.path());
        assert_eq!(files.len(), 3);
        let mut r = super::super::NpyReader::open(dir.path().join("positions.npy")).unwrap();
        assert_eq!((r.rows(), r.cols()), (3, 2));
        let mut row = [0.0; 2];
        for (p, _) in &POINTS {
            assert!(r.next_row(&mut row).unwrap());
            assert_eq!(&row, p);
        }
        let bytes = std::fs::read(dir.path().join("positions_cluster.npy")).unwrap();
        let header = String::from_utf8_lossy(&bytes[..128]);
        assert!(
            header.contains("'descr': '<i8'") && header.contains("'shape': (3,)"),
            "{header}"
        );
        let values: Vec<i64> = bytes[128..]
            .chunks(8)
            .map(|c| i64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(values, [7, 7, 9]);
    }

    #[test]
    fn lattice_sites_are_int64_in_npy_and_exact_in_text() {
        let dir = tempfile::tempdir().unwrap();
        // Beyond 2^53, where a float64 would round the site.
        let far = (1i64 << 60) + 1;
        let attributes = [Attribute {
            name: "cluster",
            labels: None,
        }];
        let set = PointSet {
            n: 2,
            axes: &["x1", "x2"],
            integer_coordinates: true,
            attributes: &attributes,
            index: None,
            title: "two sites",
            parent: None,
        };
        for format in [PointFormat::Npy, PointFormat::Csv, PointFormat::Xyz] {
            write_points(dir.path(), "sites", format, &set, &mut |f| {
                f(Coords::Int(&[3, -4]), &[0])?;
                f(Coords::Int(&[far, 0]), &[1])?;
                Ok(())
            })
            .unwrap();
        }
        let bytes = std::fs::read(dir.path().join("sites.npy")).unwrap();
        let header = String::from_utf8_lossy(&bytes[..128]);
        assert!(
            header.contains("'descr': '<i8'") && header.contains("'shape': (2, 2)"),
            "{header}"
        );
        let values: Vec<i64> = bytes[128..]
            .chunks(8)
            .map(|c| i64::from_le_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(values, [3, -4, far, 0]);
        let csv = std::fs::read_to_string(dir.path().join("sites.csv")).unwrap();
        assert_eq!(csv, format!("x1,x2,cluster\n3,-4,0\n{far},0,1\n"));
        let xyz = std::fs::read_to_string(dir.path().join("sites.xyz")).unwrap();
        assert_eq!(xyz.lines().nth(3), Some(format!("C {far} 0 0 1").as_str()));
        // A float point in an integer set is refused, and leaves no file.
        let r = write_points(dir.path(), "mixed", PointFormat::Npy, &set, &mut |f| {
            f(Coords::Float(&[0.5, 0.0]), &[0])?;
            f(Coords::Int(&[0, 0]), &[0])?;
            Ok(())
        });
        assert!(r.is_err());
        assert!(!dir.path().join("mixed.npy").exists());
    }

    #[test]
    fn a_visitor_that_disagrees_with_the_count_is_an_error() {
        let dir = tempfile::tempdir().unwrap();
        for format in [
            PointFormat::Csv,
            PointFormat::Npy,
            PointFormat::Vtk,
            PointFormat::Xyz,
        ] {
            let r = write_points(dir.path(), "short", format, &set(), &mut |f| {
                f(Coords::Float(&[0.0, 0.0]), &[0, 0])?;
                Ok(())
            });
            assert!(r.is_err(), "{format:?}");
            assert!(
                !dir.path()
                    .join(format!("short.{}", format.extension()))
                    .exists()
            );
        }
    }
}
