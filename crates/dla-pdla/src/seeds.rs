//! Growth from a given set of particles (`--seed-set PATH`): the seeds read from a positions
//! file in any format `dla` writes (`.npy`, `.csv`, `.bin`, `.xyz`, `.vtk`), so that a run
//! can grow on a previous run's cluster, on a pattern, or on a line of particles. Every seed
//! is stored first, in the file's order, with parent `-1` (each starts a tree), and walkers are
//! born on the sphere around the origin that encloses them all; on a substrate they must lie in
//! the strip and on or above it.
//!
//! `.xyz` and `.vtk` hold three coordinates: a 2D file's third is 0 and is dropped; 4D and 5D
//! seeds need `.npy`, `.csv` or `.bin`.

use std::path::Path;

/// Most seeds a set may hold: they are stored before any walker starts, and a set this large
/// is a cluster to resume (`--resume`), not to seed.
pub const MAX_SEEDS: usize = 10_000_000;

/// Farthest a seed may lie from the origin, in diameters: the birth sphere encloses every
/// seed, and walkers born on a sphere far larger than the set's own size would take very long
/// to find it.
pub const MAX_SEED_RADIUS: f64 = 1e6;

/// The seeds of the file at `path`, `D` coordinates each. Errors name the file and what is
/// wrong with it, in one line.
pub fn read<const D: usize>(path: &Path) -> Result<Vec<[f64; D]>, String> {
    let ext = path
        .extension()
        .and_then(|e| e.to_str())
        .unwrap_or("")
        .to_ascii_lowercase();
    let at = |why: String| format!("--seed-set {}: {why}", path.display());
    let seeds = match ext.as_str() {
        #[cfg(feature = "files")]
        "npy" => read_npy::<D>(path),
        #[cfg(not(feature = "files"))]
        "npy" => Err("reading .npy needs the `files` feature of dla-pdla".to_string()),
        "csv" => read_csv::<D>(path),
        "bin" => read_bin::<D>(path),
        "xyz" => read_xyz::<D>(path),
        "vtk" => read_vtk::<D>(path),
        _ => Err("not a positions file (.npy, .csv, .bin, .xyz or .vtk)".to_string()),
    }
    .map_err(at)?;
    if seeds.is_empty() {
        return Err(at("holds no particle".into()));
    }
    if seeds.len() > MAX_SEEDS {
        return Err(at(format!(
            "holds {} particles, more than {MAX_SEEDS} (resume a run instead)",
            seeds.len()
        )));
    }
    for (i, p) in seeds.iter().enumerate() {
        let r = p.iter().map(|x| x * x).sum::<f64>().sqrt();
        if !r.is_finite() || r > MAX_SEED_RADIUS {
            return Err(at(format!(
                "particle {i} at {p:?} is not within {MAX_SEED_RADIUS:e} diameters of the origin"
            )));
        }
    }
    Ok(seeds)
}

#[cfg(feature = "files")]
fn read_npy<const D: usize>(path: &Path) -> Result<Vec<[f64; D]>, String> {
    // The reader's messages name the file, which `read` names already.
    let prefix = format!("{}: ", path.display());
    let why = |e: run_io::NpyError| e.to_string().replace(&prefix, "");
    let mut r = run_io::NpyReader::open(path).map_err(why)?;
    if r.cols() != D {
        return Err(format!("{} columns, not {D}", r.cols()));
    }
    let mut out = Vec::new();
    let mut p = [0.0; D];
    while r.read_beyond(&mut p).map_err(why)? {
        out.push(p);
        if out.len() > MAX_SEEDS {
            break;
        }
    }
    Ok(out)
}

fn read_text(path: &Path) -> Result<String, String> {
    std::fs::read_to_string(path).map_err(|e| e.to_string())
}

/// A CSV with a header naming the axes `x`, `y`, ... (other columns, such as `parent`, are
/// ignored).
fn read_csv<const D: usize>(path: &Path) -> Result<Vec<[f64; D]>, String> {
    let text = read_text(path)?;
    let mut lines = text.lines();
    let header: Vec<&str> = lines
        .next()
        .ok_or("empty")?
        .split(',')
        .map(str::trim)
        .collect();
    const AXES: [&str; 5] = ["x", "y", "z", "w", "v"];
    let cols: Vec<usize> = AXES[..D]
        .iter()
        .map(|a| {
            header
                .iter()
                .position(|h| h == a)
                .ok_or_else(|| format!("no column `{a}` for {D}D in the header"))
        })
        .collect::<Result<_, _>>()?;
    let mut out = Vec::new();
    for (k, line) in lines.enumerate().filter(|(_, l)| !l.trim().is_empty()) {
        let fields: Vec<&str> = line.split(',').map(str::trim).collect();
        let mut p = [0.0; D];
        for (i, &c) in cols.iter().enumerate() {
            p[i] = fields
                .get(c)
                .and_then(|f| f.parse().ok())
                .ok_or_else(|| format!("line {}: not a number in column {}", k + 2, c + 1))?;
        }
        out.push(p);
    }
    Ok(out)
}

/// `positions.bin`: `DLAPOS01` or `DLAPOS02`, `u32` dimension, `u64` count, the coordinates
/// (little-endian).
fn read_bin<const D: usize>(path: &Path) -> Result<Vec<[f64; D]>, String> {
    let bytes = std::fs::read(path).map_err(|e| e.to_string())?;
    if bytes.len() < 20 || !(bytes[..8] == *b"DLAPOS01" || bytes[..8] == *b"DLAPOS02") {
        return Err("not a dla positions.bin (no DLAPOS01/DLAPOS02 header)".into());
    }
    let dim = u32::from_le_bytes(bytes[8..12].try_into().expect("4 bytes")) as usize;
    let n = u64::from_le_bytes(bytes[12..20].try_into().expect("8 bytes"));
    if dim != D {
        return Err(format!("{dim}D positions, not {D}D"));
    }
    let need = (n as u128) * (D as u128) * 8 + 20;
    if (bytes.len() as u128) < need || n as usize > MAX_SEEDS {
        return Err(format!(
            "{n} particles announced, {} bytes held",
            bytes.len()
        ));
    }
    Ok((0..n as usize)
        .map(|i| {
            std::array::from_fn(|a| {
                let at = 20 + (i * D + a) * 8;
                f64::from_le_bytes(bytes[at..at + 8].try_into().expect("8 bytes"))
            })
        })
        .collect())
}

/// Three coordinates into `D` (2D or 3D): a 2D particle's third must be 0.
fn from_three<const D: usize>(c: [f64; 3], i: usize) -> Result<[f64; D], String> {
    if D > 3 {
        return Err(format!(
            "holds three coordinates, not {D}: use .npy, .csv or .bin"
        ));
    }
    if D == 2 && c[2] != 0.0 {
        return Err(format!("particle {i} has z = {}, not a 2D position", c[2]));
    }
    Ok(std::array::from_fn(|a| c[a]))
}

/// Extended XYZ: a count, a comment line, then `species x y z ...` per particle.
fn read_xyz<const D: usize>(path: &Path) -> Result<Vec<[f64; D]>, String> {
    let text = read_text(path)?;
    let mut lines = text.lines();
    let n: usize = lines
        .next()
        .and_then(|l| l.trim().parse().ok())
        .ok_or("the first line is not a particle count")?;
    if n > MAX_SEEDS {
        return Err(format!("{n} particles, more than {MAX_SEEDS}"));
    }
    lines.next().ok_or("no comment line")?;
    let mut out = Vec::with_capacity(n);
    for i in 0..n {
        let line = lines
            .next()
            .ok_or_else(|| format!("{i} particles of {n}"))?;
        let f: Vec<&str> = line.split_whitespace().collect();
        let mut c = [0.0; 3];
        for a in 0..3 {
            c[a] = f
                .get(a + 1)
                .and_then(|v| v.parse().ok())
                .ok_or_else(|| format!("particle {i}: not three coordinates"))?;
        }
        out.push(from_three::<D>(c, i)?);
    }
    Ok(out)
}

/// Legacy VTK as `dla` writes it: `POINTS n double` followed by `3 n` big-endian doubles.
fn read_vtk<const D: usize>(path: &Path) -> Result<Vec<[f64; D]>, String> {
    let bytes = std::fs::read(path).map_err(|e| e.to_string())?;
    let key = b"\nPOINTS ";
    let at = bytes
        .windows(key.len())
        .position(|w| w == key)
        .ok_or("no POINTS section")?
        + key.len();
    let end = at
        + bytes[at..]
            .iter()
            .position(|&b| b == b'\n')
            .ok_or("truncated")?;
    let head = std::str::from_utf8(&bytes[at..end]).map_err(|_| "a bad POINTS line")?;
    let mut words = head.split_whitespace();
    let n: usize = words
        .next()
        .and_then(|w| w.parse().ok())
        .ok_or("a bad POINTS count")?;
    if words.next() != Some("double") {
        return Err("POINTS are not doubles".into());
    }
    let body = &bytes[end + 1..];
    if n > MAX_SEEDS || body.len() < n * 24 {
        return Err(format!("{n} points announced, {} bytes held", body.len()));
    }
    (0..n)
        .map(|i| {
            let c: [f64; 3] = std::array::from_fn(|a| {
                let k = (i * 3 + a) * 8;
                f64::from_be_bytes(body[k..k + 8].try_into().expect("8 bytes"))
            });
            from_three::<D>(c, i)
        })
        .collect()
}
