//! The CSVs the experiments write, read back by column name for their charts
//! ([`super::replot`]).

use anyhow::{Context, Result};
use csv::StringRecord;
use std::path::{Path, PathBuf};

/// A CSV read whole, its columns looked up by name.
#[derive(Debug)]
pub struct Csv {
    path: PathBuf,
    head: StringRecord,
    /// The data rows.
    pub rows: Vec<StringRecord>,
}

impl Csv {
    /// Reads `path`.
    pub fn read(path: &Path) -> Result<Self> {
        let mut r =
            csv::Reader::from_path(path).with_context(|| format!("reading {}", path.display()))?;
        let head = r.headers()?.clone();
        let rows = r
            .records()
            .collect::<Result<Vec<_>, _>>()
            .with_context(|| format!("reading {}", path.display()))?;
        anyhow::ensure!(!rows.is_empty(), "{}: no data rows", path.display());
        Ok(Csv {
            path: path.to_path_buf(),
            head,
            rows,
        })
    }

    /// The index of column `name`.
    fn col(&self, name: &str) -> Result<usize> {
        self.head
            .iter()
            .position(|h| h == name)
            .with_context(|| format!("{}: no column {name}", self.path.display()))
    }

    /// Column `name` as text.
    pub fn text(&self, name: &str) -> Result<Vec<String>> {
        let c = self.col(name)?;
        Ok(self
            .rows
            .iter()
            .map(|r| r.get(c).unwrap_or("").to_string())
            .collect())
    }

    /// Column `name` as numbers (`NaN` included).
    pub fn num(&self, name: &str) -> Result<Vec<f64>> {
        let c = self.col(name)?;
        self.rows
            .iter()
            .map(|r| {
                let s = r.get(c).unwrap_or("");
                s.parse::<f64>().with_context(|| {
                    format!("{}: {name} {s:?} is not a number", self.path.display())
                })
            })
            .collect()
    }

    /// The rows grouped by the values of the columns `keys`, groups in the order of their
    /// first row: `(key values, row indices)`.
    pub fn groups(&self, keys: &[&str]) -> Result<Vec<(Vec<String>, Vec<usize>)>> {
        let cols: Vec<Vec<String>> = keys.iter().map(|k| self.text(k)).collect::<Result<_>>()?;
        let mut out: Vec<(Vec<String>, Vec<usize>)> = Vec::new();
        for i in 0..self.rows.len() {
            let key: Vec<String> = cols.iter().map(|c| c[i].clone()).collect();
            match out.iter_mut().find(|g| g.0 == key) {
                Some(g) => g.1.push(i),
                None => out.push((key, vec![i])),
            }
        }
        Ok(out)
    }

    /// The one value of column `name` (a summary's lattice, say), or an error if the rows
    /// disagree.
    pub fn single(&self, name: &str) -> Result<String> {
        let v = self.text(name)?;
        anyhow::ensure!(
            v.iter().all(|x| *x == v[0]),
            "{}: the rows differ in {name}",
            self.path.display()
        );
        Ok(v[0].clone())
    }
}
