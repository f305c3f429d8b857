//! Accuracy against speed for DLA: sweeps of `--precision`, `--step-min` and the far field,
//! measuring microseconds per particle against the error of the fractal dimension and of the
//! R_g prefactor (both against the most exact setting), the Pareto fronts and where the
//! defaults sit on them, in 2D and 3D and for the far-field modes at 1e6 particles; then the
//! distribution of `vpdist` errors against the exact nearest distance.

mod pareto;
mod setting;
mod sweep;
mod vpdist;

pub use pareto::{pareto, replot};
pub use setting::Setting;
pub use sweep::Sweep;
pub use vpdist::vpdist_chart;

use super::Ctx;
use anyhow::Result;
use dla_pdla::FarField;

/// The near-field sweep in 2D: precision and step; the first is the reference (exact search,
/// the shortest step, exact return).
pub fn settings_2d() -> Vec<Setting> {
    let s = |precision, step_min| Setting::new(precision, step_min, FarField::Return);
    let no_map = Setting {
        distance_map: false,
        ..s(2.0, 0.5)
    };
    vec![
        s(f64::INFINITY, 0.05),
        s(f64::INFINITY, 0.1),
        s(1.0, 0.5),
        s(2.0, 0.5),
        s(4.0, 0.5),
        s(8.0, 0.5),
        s(f64::INFINITY, 0.5),
        s(2.0, 1.0),
        s(2.0, 0.25),
        Setting::default_walk(),
        s(1.0, 1.0),
        s(2.0, 0.5).jump(100.0),
        no_map,
        Setting::paper(),
    ]
}

/// The far-field sweep in 2D at large N: the default (exact return, the reference) against
/// the paper's jump-and-kill rule at several death radii, and the paper's whole walk.
pub fn settings_far_field() -> Vec<Setting> {
    let d = Setting::default_walk();
    vec![
        d,
        d.jump(10.0),
        d.jump(100.0),
        d.jump(1000.0),
        Setting::paper(),
    ]
}

/// The 3D sweep: precision and step, with the paper's walk; the first is the reference.
pub fn settings_3d() -> Vec<Setting> {
    let s = |precision, step_min| Setting::new(precision, step_min, FarField::Return);
    vec![
        s(f64::INFINITY, 0.05),
        s(f64::INFINITY, 0.1),
        Setting::default_walk(),
        s(4.0, 0.1),
        s(2.0, 0.25),
        s(2.0, 0.5),
        s(2.0, 1.0),
        Setting::paper(),
    ]
}

/// Run the sweeps and write `accuracy.md`.
pub fn run(ctx: &Ctx) -> Result<()> {
    let n2 = ctx.scale.pick(1_500, 10_000, 100_000);
    let mut doc = ctx.doc("Accuracy against speed: DLA in 2D and 3D");
    doc.p(
        "Each sweep grows, for every setting, one ensemble of clusters with the `dla` binary \
         (`dla --seeds ...`), the same seeds for every setting, its members two at a time, one \
         per core; the time is the member's CPU time per particle (its process's user and \
         system time, from `run.json`), which another job on a shared host inflates far less \
         than the wall time, so settings run at different moments compare. Errors are against the sweep's reference, its first row. The \
         R_g prefactor is A in R_g = A N^(1/D_ref), taken per cluster as the mean of \
         ln R_g - ln N / D_ref over the fitted samples with the reference's D, so it measures \
         the clusters' size at fixed N without the noise of a free intercept; its relative \
         error is ln A - ln A_ref. The Pareto front is over (microseconds per particle, \
         |error|): no other setting is both faster and closer. `--precision` changes only \
         speed (a lower bound on the distance to the cluster makes a shorter exact jump), \
         `--step-min` and the far field change the walk. The paper's walk is \
         `dla --paper-settings` (`--far-field jump --death-ratio 100 --step-min 0.5 \
         --precision 2 --distance-map off`).",
    );
    let sweeps = [
        (
            "2D, near field",
            "The reference is exact nearest-distance search (`--precision inf`), the shortest \
             near-field step (`--step-min 0.05`) and the exact far-field return.",
            Sweep {
                title: format!("2D DLA, N = {n2}"),
                dim: 2,
                n: n2,
                members: ctx.scale.pick(2, 4, 8),
                settings: settings_2d(),
                stem: "accuracy",
            },
        ),
        (
            "2D, far field at large N",
            "The reference is the default (exact far-field return, which kills no walker); the \
             other rows replace it by the paper's rule, a jump of |p| - R_ext - 1 with walkers \
             relaunched on the birth circle beyond the death radius R_d = ratio x R_b, whose \
             bias shrinks as the ratio grows, and the paper's whole walk.",
            Sweep {
                title: format!(
                    "2D DLA far field, N = {}",
                    ctx.scale.pick(1_500, 30_000, 1_000_000)
                ),
                dim: 2,
                n: ctx.scale.pick(1_500, 30_000, 1_000_000),
                members: ctx.scale.pick(2, 2, 6),
                settings: settings_far_field(),
                stem: "accuracy_farfield",
            },
        ),
        (
            "3D, near field",
            "The reference is exact nearest-distance search, the shortest near-field step \
             (0.05) and the exact far-field return, as in 2D.",
            Sweep {
                title: format!("3D DLA, N = {}", ctx.scale.pick(1_000, 10_000, 100_000)),
                dim: 3,
                n: ctx.scale.pick(1_000, 10_000, 100_000),
                members: ctx.scale.pick(2, 4, 8),
                settings: settings_3d(),
                stem: "accuracy_3d",
            },
        ),
    ];
    for (heading, reference, sweep) in &sweeps {
        doc.h2(heading);
        doc.p(&format!(
            "{} clusters of N = {} particles in {}D per setting (seeds {}..{}). {reference}",
            sweep.members,
            sweep.n,
            sweep.dim,
            ctx.seed,
            ctx.seed + sweep.members - 1
        ));
        sweep.run(ctx, &mut doc)?;
    }
    vpdist::vpdist_errors(ctx, &mut doc, n2)?;
    doc.write(&ctx.path("accuracy.md"))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn every_sweep_covers_the_default_and_the_papers_walk() {
        for s in [settings_2d(), settings_far_field(), settings_3d()] {
            assert!(s.iter().any(|x| *x == Setting::default_walk()));
            assert!(s.iter().any(|x| *x == Setting::paper()));
        }
        assert!(settings_2d()[0].precision.is_infinite());
        assert!(settings_3d()[0].precision.is_infinite());
    }
}
