//! Legacy VTK 3.0 point sets (the `vtk` format of [`super`]): binary (big-endian), an
//! `UNSTRUCTURED_GRID` of the points with one cell per point (a vertex, or with parents a line
//! to the parent) and the index and attributes as point scalars.

use super::{PointSet, VTK_MAX_POINTS, Visitor, kind_error};
use crate::OutputError;
use crate::atomic::AtomicFile;
use std::io::{self, BufWriter, Write};
use std::path::Path;

/// Legacy VTK 3.0, binary (big-endian): an `UNSTRUCTURED_GRID` of `POINTS` (float64, z = 0 in
/// the plane; only the first three axes of a higher-dimensional set) with one vertex cell
/// (`CELL_TYPES` 1) per point, so that every viewer draws them, and the index and the
/// attributes as `POINT_DATA` scalars. An unstructured grid rather than `POLYDATA`: the light
/// readers (meshio) read only unstructured grids.
pub(super) fn write_vtk(
    path: &Path,
    set: &PointSet<'_>,
    visit: &mut Visitor<'_>,
) -> Result<(), OutputError> {
    let n = set.n;
    // VTK's legacy cells and scalars are 32-bit.
    let n32 = i32::try_from(n)
        .ok()
        .filter(|_| n <= VTK_MAX_POINTS)
        .ok_or_else(|| {
            io::Error::new(
                io::ErrorKind::InvalidInput,
                format!("{n} points are too many for legacy VTK's 32-bit cells; use npy"),
            )
        })?;
    let mut f = AtomicFile::create(path)?;
    {
        let mut b = BufWriter::new(&mut f);
        let title: String = set.title.chars().filter(|c| *c != '\n').take(255).collect();
        write!(
            b,
            "# vtk DataFile Version 3.0\n{title}\nBINARY\nDATASET UNSTRUCTURED_GRID\n\
             POINTS {n} double\n"
        )?;
        let mut count = 0u64;
        visit(&mut |p, _| {
            count += 1;
            if p.is_int() != set.integer_coordinates {
                return Err(kind_error(set));
            }
            for i in 0..3 {
                b.write_all(&p.float(i).to_be_bytes())?;
            }
            Ok(())
        })?;
        if count != n {
            return Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!("{}: {count} points visited, {n} announced", path.display()),
            )
            .into());
        }
        match set.parent {
            None => {
                // Each cell: its point count (1) and its point; then each cell's type,
                // VTK_VERTEX (1).
                write!(b, "\nCELLS {n} {}\n", 2 * n)?;
                for i in 0..n32 {
                    b.write_all(&1i32.to_be_bytes())?;
                    b.write_all(&i.to_be_bytes())?;
                }
                write!(b, "\nCELL_TYPES {n}\n")?;
                for _ in 0..n32 {
                    b.write_all(&1i32.to_be_bytes())?;
                }
            }
            Some(k) => write_vtk_links(&mut b, n, k, visit)?,
        }
        write!(b, "\nPOINT_DATA {n}\n")?;
        if let Some(name) = set.index {
            write!(b, "SCALARS {name} int 1\nLOOKUP_TABLE default\n")?;
            for i in 0..n32 {
                b.write_all(&i.to_be_bytes())?;
            }
            writeln!(b)?;
        }
        for (k, a) in set.attributes.iter().enumerate() {
            write!(b, "SCALARS {} int 1\nLOOKUP_TABLE default\n", a.name)?;
            visit(&mut |_, values| {
                let v = values.get(k).copied().unwrap_or(0);
                let v = i32::try_from(v).map_err(|_| {
                    io::Error::new(
                        io::ErrorKind::InvalidData,
                        format!("{} = {v} does not fit VTK's 32-bit scalars", a.name),
                    )
                })?;
                b.write_all(&v.to_be_bytes())
            })?;
            writeln!(b)?;
        }
        b.flush()?;
    }
    f.commit()?;
    Ok(())
}

/// The cells of a point set with parents: point `i` with parent `p >= 0` is the line cell
/// `(p, i)` (VTK_LINE, 3), a root the vertex cell `(i)` (VTK_VERTEX, 1). A parent that is not
/// another point's index is an error.
fn write_vtk_links(
    b: &mut impl Write,
    n: u64,
    k: usize,
    visit: &mut Visitor<'_>,
) -> Result<(), OutputError> {
    let parent_of = |values: &[i64], i: u64| -> io::Result<Option<i32>> {
        match values.get(k).copied() {
            Some(-1) => Ok(None),
            Some(p) if p >= 0 && (p as u64) < n && p as u64 != i => Ok(Some(p as i32)),
            other => Err(io::Error::new(
                io::ErrorKind::InvalidData,
                format!("point {i}: parent {other:?} is not another point's index or -1"),
            )),
        }
    };
    let mut roots = 0u64;
    let mut i = 0u64;
    visit(&mut |_, values| {
        roots += u64::from(parent_of(values, i)?.is_none());
        i += 1;
        Ok(())
    })?;
    let lines = n - roots;
    write!(b, "\nCELLS {n} {}\n", 2 * roots + 3 * lines)?;
    let mut i = 0u64;
    visit(&mut |_, values| {
        match parent_of(values, i)? {
            None => {
                b.write_all(&1i32.to_be_bytes())?;
                b.write_all(&(i as i32).to_be_bytes())?;
            }
            Some(p) => {
                b.write_all(&2i32.to_be_bytes())?;
                b.write_all(&p.to_be_bytes())?;
                b.write_all(&(i as i32).to_be_bytes())?;
            }
        }
        i += 1;
        Ok(())
    })?;
    write!(b, "\nCELL_TYPES {n}\n")?;
    let mut i = 0u64;
    visit(&mut |_, values| {
        let kind: i32 = if parent_of(values, i)?.is_some() {
            3
        } else {
            1
        };
        i += 1;
        b.write_all(&kind.to_be_bytes())
    })?;
    Ok(())
}

#[cfg(test)]
mod tests {
    use super::super::tests::{POINTS, set, write};
    use super::super::{Coords, PointFormat, write_points};

    #[test]
    fn vtk_has_points_vertex_cells_and_scalars() {
        let dir = tempfile::tempdir().unwrap();
        write(PointFormat::Vtk, dir.path());
        let bytes = std::fs::read(dir.path().join("positions.vtk")).unwrap();
        let head = "# vtk DataFile Version 3.0\nthree points\nBINARY\nDATASET UNSTRUCTURED_GRID\n\
             POINTS 3 double\n";
        assert!(bytes.starts_with(head.as_bytes()));
        let at = head.len();
        let xyz: Vec<f64> = bytes[at..at + 72]
            .chunks(8)
            .map(|c| f64::from_be_bytes(c.try_into().unwrap()))
            .collect();
        assert_eq!(xyz, [0.0, 1.5, 0.0, 2.0, -1.0, 0.0, 3.25, 4.0, 0.0]);
        let rest = &bytes[at + 72..];
        let find = |s: &str| {
            rest.windows(s.len())
                .position(|w| w == s.as_bytes())
                .unwrap_or_else(|| panic!("{s:?} missing"))
        };
        let v = find("CELLS 3 6\n") + "CELLS 3 6\n".len();
        assert_eq!(&rest[v..v + 8], &[0, 0, 0, 1, 0, 0, 0, 0]);
        let t = find("CELL_TYPES 3\n") + "CELL_TYPES 3\n".len();
        assert_eq!(&rest[t..t + 12], &[0, 0, 0, 1, 0, 0, 0, 1, 0, 0, 0, 1]);
        find("POINT_DATA 3\n");
        let c = find("SCALARS cluster int 1\nLOOKUP_TABLE default\n")
            + "SCALARS cluster int 1\nLOOKUP_TABLE default\n".len();
        let ids: Vec<i32> = rest[c..c + 12]
            .chunks(4)
            .map(|b| i32::from_be_bytes(b.try_into().unwrap()))
            .collect();
        assert_eq!(ids, [7, 7, 9]);
        find("SCALARS arrival int 1\n");
        find("SCALARS species int 1\n");
    }

    /// With parents, each point with one is a line cell from its parent, roots are vertices.
    #[test]
    fn vtk_draws_parents_as_lines() {
        let dir = tempfile::tempdir().unwrap();
        let mut s = set();
        s.parent = Some(1);
        let parents = [-1i64, 0, 1];
        write_points(dir.path(), "positions", PointFormat::Vtk, &s, &mut |f| {
            for ((p, a), parent) in POINTS.iter().zip(parents) {
                f(Coords::Float(p), &[a[0], parent])?;
            }
            Ok(())
        })
        .unwrap();
        let bytes = std::fs::read(dir.path().join("positions.vtk")).unwrap();
        let find = |s: &str| {
            bytes
                .windows(s.len())
                .position(|w| w == s.as_bytes())
                .unwrap_or_else(|| panic!("{s:?} missing"))
                + s.len()
        };
        let ints = |at: usize, k: usize| -> Vec<i32> {
            bytes[at..at + 4 * k]
                .chunks(4)
                .map(|b| i32::from_be_bytes(b.try_into().unwrap()))
                .collect()
        };
        assert_eq!(ints(find("CELLS 3 8\n"), 8), [1, 0, 2, 0, 1, 2, 1, 2]);
        assert_eq!(ints(find("CELL_TYPES 3\n"), 3), [1, 3, 3]);
        // A parent that names no point is refused.
        let e = write_points(dir.path(), "positions", PointFormat::Vtk, &s, &mut |f| {
            for (p, a) in &POINTS {
                f(Coords::Float(p), &[a[0], 5])?;
            }
            Ok(())
        });
        assert!(e.is_err());
    }
}
