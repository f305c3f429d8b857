//! The schema of every output: for each file a model writes, each column or array with its
//! name, dtype and unit, and the Python attribute that holds the same values. Each model
//! declares its files once (`dla_pdla::output::SCHEMA`, `dlca::output::SCHEMA`,
//! `animat::output::SCHEMA`); the writers take their CSV headers and attribute names from it,
//! a test holds `docs/outputs.md`'s tables to it ([`markdown_rows`]), and the Python package
//! exports it (`aggsim._schema(model)`, the [`serde`] form of these types) for the test that
//! checks a run of the binary and the same run from Python against it and each other.
//!
//! The rule it states: a quantity has one name and one dtype in every output. A CSV column,
//! the suffix of a positions attribute's `.npy` file and the Python key or attribute are
//! spelled alike; `.npy` files and Python arrays have the dtype listed; CSV holds the same
//! values as text (integers without a fractional part, booleans as `true`/`false`, coded
//! values such as a species by their names).

use serde::Serialize;

/// The type of a column or array, as NumPy names it.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Dtype {
    /// Counts: particles, sweeps, steps, clusters.
    Uint64,
    /// Lattice sites and cells (negative on the unbounded plane), ids, codes, ages.
    Int64,
    /// Lengths, times, off-lattice coordinates.
    Float64,
    /// Flags (`true`/`false` in CSV).
    Bool,
}

impl Dtype {
    /// NumPy's name of the dtype (`numpy.dtype(name)`).
    pub fn name(self) -> &'static str {
        match self {
            Dtype::Uint64 => "uint64",
            Dtype::Int64 => "int64",
            Dtype::Float64 => "float64",
            Dtype::Bool => "bool",
        }
    }
}

/// One column of a CSV file, or one attribute array of a positions set.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Column {
    /// The CSV column, the `.npy` suffix, the Python key or attribute.
    pub name: &'static str,
    /// Its dtype in `.npy` and in Python.
    pub dtype: Dtype,
    /// Its unit (or what it counts).
    pub unit: &'static str,
    /// The option that adds it (`--timing`), if it is not always written.
    pub when: Option<&'static str>,
    /// Names of the codes `0, 1, ...` that CSV and XYZ write instead of the numbers.
    pub labels: Option<&'static [&'static str]>,
    /// A wall-clock measurement: it differs between two runs of the same seed.
    pub measured: bool,
}

impl Column {
    /// An always-written, deterministic column without labels.
    pub const fn new(name: &'static str, dtype: Dtype, unit: &'static str) -> Self {
        Column {
            name,
            dtype,
            unit,
            when: None,
            labels: None,
            measured: false,
        }
    }

    /// The column written only with the option `flag`.
    pub const fn when(mut self, flag: &'static str) -> Self {
        self.when = Some(flag);
        self
    }

    /// The column of codes whose names are `labels`.
    pub const fn labels(mut self, labels: &'static [&'static str]) -> Self {
        self.labels = Some(labels);
        self
    }

    /// The column as a wall-clock measurement.
    pub const fn measured(mut self) -> Self {
        self.measured = true;
        self
    }
}

/// How the coordinates of a positions set are named.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Axes {
    /// `x`, `y`: the plane.
    Plane,
    /// `x`, `y`, `z`, `w`, `v`: the first `D` of them.
    Letters,
    /// `x1`, `x2`, ... `xd`.
    Numbered,
}

impl Axes {
    /// The names of the first `dim` coordinates.
    pub fn names(self, dim: usize) -> Vec<String> {
        match self {
            Axes::Plane | Axes::Letters => ["x", "y", "z", "w", "v"]
                .iter()
                .take(dim)
                .map(|s| s.to_string())
                .collect(),
            Axes::Numbered => (1..=dim).map(|a| format!("x{a}")).collect(),
        }
    }

    fn show(self) -> &'static str {
        match self {
            Axes::Plane => "`x`, `y`",
            Axes::Letters => "`x`, `y` (`z`, `w`, `v`)",
            Axes::Numbered => "`x1` ... `xd`",
        }
    }
}

/// What kind of output a file is.
#[derive(Debug, Clone, Copy, Serialize)]
#[serde(tag = "kind", rename_all = "lowercase")]
pub enum Form {
    /// `FILE` is a CSV file with the columns as its header; Python's attribute is a dict of
    /// arrays with the same keys.
    Csv,
    /// A positions set of `run_io::points`, `FILE` its stem: `FILE.csv` (the
    /// coordinates, then the columns), `FILE.npy` `(N, D)` with `FILE_<column>.npy` `(N,)`,
    /// `FILE.vtk`, `FILE.xyz`. Python's attribute is the `(N, D)` coordinates, and each
    /// column is the result's attribute of its own name.
    Points {
        /// The coordinates' names.
        axes: Axes,
        /// Their dtype.
        dtype: Dtype,
        /// Their unit.
        unit: &'static str,
    },
}

/// One file (or positions set) of a model.
#[derive(Debug, Clone, Copy, Serialize)]
pub struct Output {
    /// The file name, or the stem of a positions set.
    pub file: &'static str,
    /// CSV file or positions set.
    pub form: Form,
    /// The attribute of the Python result holding it.
    pub python: &'static str,
    /// The option that writes it, if it is not always written.
    pub when: Option<&'static str>,
    /// Its columns (a positions set: its attributes, after the coordinates).
    pub columns: &'static [Column],
}

impl Output {
    /// The CSV header: every column, those added by an option only if `optional`.
    pub fn header(&self, optional: bool) -> Vec<&'static str> {
        self.columns
            .iter()
            .filter(|c| optional || c.when.is_none())
            .map(|c| c.name)
            .collect()
    }

    /// The column `name`.
    ///
    /// # Panics
    /// If the output has no such column: a writer and its schema disagree.
    pub fn column(&self, name: &str) -> &Column {
        self.columns
            .iter()
            .find(|c| c.name == name)
            .unwrap_or_else(|| panic!("{} has no column {name}", self.file))
    }
}

/// The output named `file` in `schema`.
///
/// # Panics
/// If there is none: a writer and its schema disagree.
pub fn output<'a>(schema: &'a [Output], file: &str) -> &'a Output {
    schema
        .iter()
        .find(|o| o.file == file)
        .unwrap_or_else(|| panic!("no output {file} in the schema"))
}

fn with(name: String, when: Option<&str>) -> String {
    match when {
        Some(w) => format!("{name} (with `{w}`)"),
        None => name,
    }
}

/// The rows of the table `docs/outputs.md` shows for `schema`, header first: `file`,
/// `column or array`, `dtype`, `unit`, `Python`; one row per column (a positions set: one for
/// its coordinates, then one per attribute). Compare with
/// `core_lattice::spec::markdown_table` of the document.
pub fn markdown_rows(schema: &[Output]) -> Vec<Vec<String>> {
    let mut rows = vec![
        ["file", "column or array", "dtype", "unit", "Python"]
            .map(String::from)
            .to_vec(),
    ];
    for o in schema {
        let (file, unit_of) = match o.form {
            Form::Csv => (format!("`{}`", o.file), None),
            Form::Points { axes, dtype, unit } => {
                let file = format!("`{}.csv`, `.npy`, `.vtk`, `.xyz`", o.file);
                rows.push(vec![
                    with(file.clone(), o.when),
                    format!("{} (`{}.npy`: `(N, D)`)", axes.show(), o.file),
                    dtype.name().to_string(),
                    unit.to_string(),
                    format!("`{}` `(N, D)`", o.python),
                ]);
                (file, Some(()))
            }
        };
        for c in o.columns {
            let python = match o.form {
                Form::Csv => format!("`{}[\"{}\"]`", o.python, c.name),
                Form::Points { .. } => format!("`{}`", c.name),
            };
            let column = match unit_of {
                Some(()) => format!("`{}` (`{}_{}.npy`)", c.name, o.file, c.name),
                None => format!("`{}`", c.name),
            };
            let unit = match c.labels {
                Some(l) => {
                    let codes: Vec<String> = l
                        .iter()
                        .enumerate()
                        .map(|(k, n)| format!("{k} `{n}`"))
                        .collect();
                    format!("{} (codes: {})", c.unit, codes.join(", "))
                }
                None => c.unit.to_string(),
            };
            rows.push(vec![
                with(file.clone(), o.when),
                with(column, c.when),
                c.dtype.name().to_string(),
                unit,
                python,
            ]);
        }
    }
    rows
}

/// The rows of [`markdown_rows`] as Markdown, to paste into the document.
pub fn markdown(schema: &[Output]) -> String {
    let rows = markdown_rows(schema);
    let mut s = String::new();
    for (i, r) in rows.iter().enumerate() {
        s.push_str(&format!("| {} |\n", r.join(" | ")));
        if i == 0 {
            s.push_str(&format!("|{}\n", "---|".repeat(r.len())));
        }
    }
    s
}

/// Checks the table under `heading` of the document `doc` (`docs/outputs.md`) against
/// `schema`, with a message that shows the expected table.
///
/// # Panics
/// If they differ.
pub fn check_doc(doc: &str, heading: &str, schema: &[Output]) {
    let found = core_lattice::spec::markdown_table(doc, heading);
    let expected = markdown_rows(schema);
    assert!(
        found == expected,
        "docs/outputs.md, table under `{heading}`, differs from the schema; it should read\n\n{}",
        markdown(schema)
    );
}

#[cfg(test)]
mod tests {
    use super::*;

    const SCHEMA: &[Output] = &[
        Output {
            file: "steps.csv",
            form: Form::Csv,
            python: "per_step",
            when: None,
            columns: &[
                Column::new("step", Dtype::Uint64, "steps"),
                Column::new("seconds", Dtype::Float64, "s")
                    .when("--timing")
                    .measured(),
            ],
        },
        Output {
            file: "cells",
            form: Form::Points {
                axes: Axes::Numbered,
                dtype: Dtype::Int64,
                unit: "sites",
            },
            python: "positions",
            when: Some("--positions"),
            columns: &[Column::new("kind", Dtype::Int64, "code").labels(&["a", "b"])],
        },
    ];

    #[test]
    fn headers_leave_out_optional_columns_unless_asked() {
        assert_eq!(SCHEMA[0].header(false), ["step"]);
        assert_eq!(SCHEMA[0].header(true), ["step", "seconds"]);
        assert_eq!(Axes::Numbered.names(3), ["x1", "x2", "x3"]);
        assert_eq!(Axes::Letters.names(2), ["x", "y"]);
    }

    #[test]
    fn the_markdown_table_reads_back_as_its_rows() {
        let doc = format!("## Files\n\nSome text.\n\n{}\nAfter.\n", markdown(SCHEMA));
        check_doc(&doc, "## Files", SCHEMA);
        let rows = markdown_rows(SCHEMA);
        assert_eq!(rows.len(), 1 + 2 + 2);
        assert_eq!(rows[2][1], "`seconds` (with `--timing`)");
        assert_eq!(rows[3][2], "int64");
        assert_eq!(rows[4][3], "code (codes: 0 `a`, 1 `b`)");
        assert_eq!(rows[4][4], "`kind`");
    }

    #[test]
    #[should_panic(expected = "differs from the schema")]
    fn a_wrong_dtype_in_the_document_fails() {
        let doc = markdown(SCHEMA).replace("| uint64 |", "| int64 |");
        check_doc(&format!("## Files\n\n{doc}"), "## Files", SCHEMA);
    }

    #[test]
    fn the_json_form_names_dtypes_as_numpy() {
        let v = serde_json::to_value(SCHEMA).unwrap();
        assert_eq!(v[0]["columns"][0]["dtype"], "uint64");
        assert_eq!(v[1]["form"]["kind"], "points");
        assert_eq!(v[1]["form"]["dtype"], "int64");
        assert_eq!(v[1]["columns"][0]["labels"][1], "b");
    }
}
