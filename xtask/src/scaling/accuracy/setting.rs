//! The flags of `dla` one point of an accuracy sweep changes: precision, step, far field and
//! distance map, with their labels for the tables and charts.

use dla_pdla::{FarField, Params};

/// One point of a sweep: the flags of `dla` that change the walk.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Setting {
    /// `--precision`.
    pub precision: f64,
    /// `--step-min`.
    pub step_min: f64,
    /// `--far-field`.
    pub far_field: FarField,
    /// `--death-ratio` (used by `--far-field jump` only).
    pub death_ratio: f64,
    /// `--distance-map`.
    pub distance_map: bool,
}

impl Setting {
    /// The defaults' walk with another precision, step and far field.
    pub fn new(precision: f64, step_min: f64, far_field: FarField) -> Self {
        let d = Params::default();
        Setting {
            precision,
            step_min,
            far_field,
            death_ratio: d.death_ratio,
            distance_map: d.distance_map,
        }
    }

    /// The defaults of `dla`.
    pub fn default_walk() -> Self {
        let d = Params::default();
        Setting::new(d.precision, d.step_min, d.far_field)
    }

    /// `dla --paper-settings`.
    pub fn paper() -> Self {
        let d = Params::default().paper_settings();
        Setting {
            death_ratio: d.death_ratio,
            distance_map: d.distance_map,
            ..Setting::new(d.precision, d.step_min, d.far_field)
        }
    }

    /// The `--far-field jump` walk with death radius `ratio` birth radii.
    pub fn jump(self, ratio: f64) -> Self {
        Setting {
            far_field: FarField::Jump,
            death_ratio: ratio,
            ..self
        }
    }

    pub(super) fn is_default(&self) -> bool {
        *self == Setting::default_walk()
    }

    pub(super) fn is_paper(&self) -> bool {
        *self == Setting::paper()
    }

    pub(super) fn precision_name(&self) -> String {
        if self.precision.is_finite() {
            format!("{}", self.precision)
        } else {
            "inf".into()
        }
    }

    /// `k2 s0.5 jump100`: a point label for the charts.
    pub(super) fn short(&self) -> String {
        let ff = match self.far_field {
            FarField::Return => String::new(),
            FarField::Jump => format!(" jump{}", self.death_ratio),
        };
        let map = if self.distance_map { "" } else { " no map" };
        format!("k{} s{}{ff}{map}", self.precision_name(), self.step_min)
    }

    /// `precision 2, step 0.5, jump (death ratio 100)`: the table's label.
    pub(super) fn label(&self) -> String {
        let ff = match self.far_field {
            FarField::Return => "return".to_string(),
            FarField::Jump => format!("jump (death ratio {})", self.death_ratio),
        };
        format!(
            "precision {}, step {}, {ff}{}",
            self.precision_name(),
            self.step_min,
            if self.distance_map {
                ""
            } else {
                ", distance map off"
            }
        )
    }

    /// The flags of `dla` for this setting.
    pub(super) fn flags(&self) -> Vec<String> {
        if self.is_paper() {
            return vec!["--paper-settings".into()];
        }
        let mut f = vec![
            format!("--precision={}", self.precision),
            format!("--step-min={}", self.step_min),
            format!("--far-field={}", self.far_field.name()),
            format!(
                "--distance-map={}",
                if self.distance_map { "on" } else { "off" }
            ),
        ];
        if self.far_field == FarField::Jump {
            f.push(format!("--death-ratio={}", self.death_ratio));
        }
        f
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn settings_name_their_flags() {
        assert_eq!(Setting::paper().flags(), vec!["--paper-settings"]);
        let j = Setting::default_walk().jump(10.0);
        assert!(j.flags().contains(&"--death-ratio=10".to_string()));
        assert!(
            !Setting::default_walk()
                .flags()
                .iter()
                .any(|f| f.contains("death"))
        );
        assert!(Setting::default_walk().is_default() && !Setting::paper().is_default());
    }
}
