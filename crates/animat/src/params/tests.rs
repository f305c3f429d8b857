//! Tests of parameter validation: defaults, refused values and their messages, grid-box serialisation.

use super::*;

#[test]
fn defaults_are_valid() {
    Params::default().validate().unwrap();
}

#[test]
fn bad_values_name_the_value_and_range() {
    let p = Params {
        fox_breed_p: 1.5,
        ..Params::default()
    };
    let e = p.validate().unwrap_err().to_string();
    assert_eq!(e, "--fox-breed-p 1.5 is outside the accepted range [0, 1]");
    let p = Params {
        rabbit_breed_p: f64::NAN,
        ..Params::default()
    };
    assert!(matches!(p.validate(), Err(ParamsError::Range(_))));
    let p = Params {
        vision: 0,
        ..Params::default()
    };
    assert!(
        p.validate()
            .unwrap_err()
            .to_string()
            .starts_with("--vision 0 is outside the accepted range 1..=1073741824")
    );
    let p = Params {
        grid_box: GridBox::Side(-5),
        ..Params::default()
    };
    assert!(
        p.validate()
            .unwrap_err()
            .to_string()
            .starts_with("--grid-box -5 is outside")
    );
    let p = Params {
        fox_rules: vec!["eat".into(), "fly".into()],
        ..Params::default()
    };
    assert_eq!(
        p.validate().unwrap_err().to_string(),
        "unknown fox rule \"fly\"; accepted: eat, breed, hunt, seek_mate, wander"
    );
    let p = Params {
        rabbit_rules: vec!["herd".into(), "herd".into()],
        ..Params::default()
    };
    assert!(matches!(
        p.validate(),
        Err(ParamsError::DuplicateRule { .. })
    ));
    let p = Params {
        fox_rules: vec![],
        ..Params::default()
    };
    assert_eq!(
        p.validate().unwrap_err().to_string(),
        "fox_rules is empty, so a fox would never act; give at least one of: eat, breed, hunt, seek_mate, wander"
    );
    let p = Params {
        rabbit_rules: vec![],
        rabbits: 0,
        ..Params::default()
    };
    assert_eq!(p.validate(), Ok(()));
    let p = Params {
        hungry_at: 31,
        starve: 30,
        ..Params::default()
    };
    assert!(matches!(p.validate(), Err(ParamsError::NeverHungry { .. })));
    let p = Params {
        start_radius: 10,
        ..Params::default()
    };
    assert!(matches!(
        p.validate(),
        Err(ParamsError::StartTooDense { .. })
    ));
}

#[test]
fn density_sets_the_start_radius_or_names_its_flag() {
    let mut p = Params::default();
    p.set_density(0.1).unwrap();
    assert_eq!(p.start_radius, Params::radius_for_density(2300, 0.1));
    assert_eq!(
        p.set_density(0.6).unwrap_err(),
        "--density 0.6 is outside the accepted range (0, 0.5]"
    );
    assert!(
        p.set_density(1e-30)
            .unwrap_err()
            .contains("raise --density")
    );
}

#[test]
fn grid_box_serde() {
    for (g, s) in [
        (GridBox::Side(30), "30"),
        (GridBox::None, "\"none\""),
        (GridBox::Vision, "\"vision\""),
    ] {
        assert_eq!(serde_json::to_string(&g).unwrap(), s);
        assert_eq!(serde_json::from_str::<GridBox>(s).unwrap(), g);
    }
    assert!(serde_json::from_str::<GridBox>("\"huge\"").is_err());
}
