//! Naming what differs between a checkpointed run and the flags of a `--resume`: each
//! parameter that differs, as its flag with both values, instead of a dump of the parameter
//! structs.

use serde::Serialize;

/// The parameters of a checkpointed run against those the flags give, as one text per
/// differing field, in field-name order: `--step-min 0.5 in the checkpoint, 0.1 given`. Fields are compared through
/// their serde form; a field's flag is `--` and its name with `-` for `_`, unless `renames`
/// maps it to another flag (`Some("--fill/--particles")`) or to `None` (not compared: a field
/// the resumed run may change). Empty when the runs agree.
pub fn flag_differences<T: Serialize>(
    checkpointed: &T,
    given: &T,
    renames: &[(&str, Option<&str>)],
) -> Vec<String> {
    labelled_differences(checkpointed, given, ("in the checkpoint", "given"), renames)
}

/// [`flag_differences`] with other words for the two sides: `labels = ("for seed 1", "for seed
/// 2")` gives `--size 8 for seed 1, 16 for seed 2`.
pub fn labelled_differences<T: Serialize>(
    checkpointed: &T,
    given: &T,
    labels: (&str, &str),
    renames: &[(&str, Option<&str>)],
) -> Vec<String> {
    let (la, lb) = labels;
    let (Ok(serde_json::Value::Object(old)), Ok(serde_json::Value::Object(new))) = (
        serde_json::to_value(checkpointed),
        serde_json::to_value(given),
    ) else {
        // Not a struct: compare as a whole.
        let (a, b) = (
            serde_json::to_value(checkpointed).unwrap_or_default(),
            serde_json::to_value(given).unwrap_or_default(),
        );
        return if a == b {
            Vec::new()
        } else {
            vec![format!("{} {la}, {} {lb}", text(&a), text(&b))]
        };
    };
    let mut out = Vec::new();
    for (field, a) in &old {
        let flag = match renames.iter().find(|(f, _)| f == field) {
            Some((_, None)) => continue,
            Some((_, Some(flag))) => (*flag).to_string(),
            None => format!("--{}", field.replace('_', "-")),
        };
        let b = new.get(field).cloned().unwrap_or(serde_json::Value::Null);
        if *a != b {
            out.push(format!("{flag} {} {la}, {} {lb}", text(a), text(&b)));
        }
    }
    out
}

/// A parameter value as a user would type it: strings bare, lists comma separated, an enum
/// variant with data as `variant value`, nothing as `none`.
fn text(v: &serde_json::Value) -> String {
    use serde_json::Value;
    match v {
        Value::Null => "none".into(),
        Value::Bool(b) => b.to_string(),
        Value::Number(n) => n.to_string(),
        Value::String(s) => s.clone(),
        Value::Array(items) => items.iter().map(text).collect::<Vec<_>>().join(","),
        Value::Object(map) => map
            .iter()
            .map(|(k, v)| format!("{} {}", k.to_lowercase(), text(v)))
            .collect::<Vec<_>>()
            .join(" "),
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[derive(Serialize)]
    enum Init {
        Fill(f64),
    }

    #[derive(Serialize)]
    struct P {
        step_min: f64,
        size: Vec<u64>,
        init: Init,
        max_sweeps: Option<u64>,
        keep_positions: bool,
    }

    #[test]
    fn differences_name_the_flag_and_both_values() {
        let a = P {
            step_min: 0.5,
            size: vec![64, 32],
            init: Init::Fill(0.1),
            max_sweeps: None,
            keep_positions: true,
        };
        let b = P {
            step_min: 0.1,
            size: vec![64, 64],
            init: Init::Fill(0.2),
            max_sweeps: Some(5),
            keep_positions: false,
        };
        let renames = [
            ("init", Some("--fill/--particles")),
            ("keep_positions", None),
        ];
        assert_eq!(
            flag_differences(&a, &b, &renames),
            vec![
                "--fill/--particles fill 0.1 in the checkpoint, fill 0.2 given",
                "--max-sweeps none in the checkpoint, 5 given",
                "--size 64,32 in the checkpoint, 64,64 given",
                "--step-min 0.5 in the checkpoint, 0.1 given",
            ]
        );
        assert!(flag_differences(&a, &a, &renames).is_empty());
    }
}
