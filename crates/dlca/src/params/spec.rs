//! The tests of the table of DLCA parameters ([`PARAMS`], written by [`Settings`]'s
//! declaration): it has a default for every parameter and the engine's defaults, the text
//! values read back what they show, and validation accepts each stated range's bounds and
//! refuses the nearest values outside.

use super::{Init, LATTICE_FLAGS, PARAMS, Params, Search, Settings, defaults};
use core_lattice::spec::{DeclaredParams, Input};
use serde_json::Value;

#[test]
fn the_table_has_a_default_for_every_parameter() {
    core_lattice::spec::check_table(PARAMS, defaults().keys().map(String::as_str));
    let lattice: Vec<&str> = PARAMS[..LATTICE_FLAGS].iter().map(|s| s.name).collect();
    assert_eq!(lattice, ["dim", "size", "fill", "particles"]);
    assert_eq!(Search::ALL.map(Search::name), Search::NAMES);
    for x in Search::ALL {
        assert_eq!(x.name().parse::<Search>(), Ok(x));
    }
    assert!(
        "gird"
            .parse::<Search>()
            .unwrap_err()
            .ends_with("possible values are auto, all-pairs, grid, grid-doubling, lattice")
    );
    // Every boundary of the table parses, and nothing else.
    let boundary = PARAMS.iter().find(|s| s.name == "boundary").unwrap();
    for b in boundary.range.choices() {
        assert_eq!(b.parse::<core_lattice::Boundary>().unwrap().to_string(), *b);
    }
    // The defaults are the engine's.
    let p = Settings {
        size: Some(crate::params::Sizes(vec![1024])),
        fill: Some(0.01),
        ..Settings::default()
    }
    .to_params(|_| false)
    .unwrap();
    assert_eq!(p, Params::default());
}

#[test]
fn the_text_values_read_back_what_they_show() {
    let mut s = Settings::default();
    for (name, text) in [
        ("size", "64x32"),
        ("boundary", "periodic,wall"),
        ("max_memory", "1536M"),
        ("histogram_sweeps", "1,3"),
    ] {
        assert_eq!(s.set(name, &Input::Text(text.into())), Ok(true), "{name}");
        let shown = s.to_text().into_iter().find(|(n, _)| *n == name).unwrap();
        assert_eq!(shown.1, text);
    }
    assert_eq!(s.max_memory.0, 1536 << 20);
    assert!(s.set("size", &Input::Text("64xx".into())).is_err());
    assert!(
        s.set("histogram_sweeps", &Input::Text("1,x".into()))
            .is_err()
    );
    assert_eq!(Settings::default().to_text()[12].1, "4G");
    // The sweeps of --histogram-sweeps need --histogram.
    s.size = Some(crate::params::Sizes(vec![64]));
    s.fill = Some(0.1);
    let given = |n: &str| n == "histogram_sweeps";
    assert_eq!(
        s.to_params(given).unwrap_err(),
        "--histogram-sweeps is used with --histogram only"
    );
    s.histogram = true;
    assert_eq!(s.to_params(given).unwrap().histogram_sweeps, [1, 3]);
}

/// `Params` with the parameter `name` set to `v`, as the front ends set it.
fn with(name: &str, v: &Value) -> Result<Params, String> {
    let mut s = Settings {
        size: Some(crate::params::Sizes(vec![64])),
        ..Settings::default()
    };
    let input = match v.as_u64() {
        Some(n) if name != "fill" => Input::Count(n),
        _ => Input::Real(v.as_f64().unwrap()),
    };
    if name != "fill" {
        s.fill = Some(0.01);
    }
    assert_eq!(s.set(name, &input), Ok(true), "{name}");
    s.to_params(|_| false)
}

/// Validation accepts each range's bounds and refuses the nearest values outside, naming
/// the range as the table writes it.
#[test]
fn validation_refuses_just_outside_each_stated_range() {
    core_lattice::spec::check_range_probes(PARAMS, |name, value| {
        let v: Value = serde_json::from_str(value).unwrap();
        with(name, &v).map(drop)
    });
    assert!(matches!(with("fill", &Value::from(0.5)), Ok(p) if p.init == Init::Fill(0.5)));
}
