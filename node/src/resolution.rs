//! Automatic resolution for real time: times a short trial of the case at candidate particle spacings, from
//! the coarsest up, and keeps the finest whose measured real-time factor has the requested margin. The trial
//! runs the config's own `motion.*` (so it should resemble the motion expected live: a tank at rest steps
//! faster than a sloshing one). The candidates go no coarser than the coarsest spacing the manual's
//! convergence table measures accurate for the case's scheme ([`crate::accuracy`]) unless
//! `allow_inaccurate` is set: speed does not come from silently giving up accuracy.

use crate::config::AutoResolutionCfg;
use crate::config::Loaded;
use sph::params::SimParams;
use std::sync::atomic::{AtomicBool, Ordering};
use std::time::Instant;

/// The outcome: the spacing chosen, its measured real-time factor, and every trial (spacing, factor).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Choice {
    pub particle_spacing: f64,
    pub realtime_factor: f64,
    pub trials: Vec<(f64, f64)>,
    /// The target was met (else the coarsest spacing is used anyway).
    pub met: bool,
    /// The trials' target real-time factor.
    pub target_factor: f64,
    /// Candidate spacings left out because the case is not valid at them (spacing, why), coarsest first.
    pub skipped: Vec<(f64, String)>,
    /// Why spacings up to `max_spacing` were not all tried: the coarsest accurate spacing held them back.
    pub held_by_accuracy: Option<String>,
    /// With `allow_inaccurate`, a spacing chosen coarser than the accurate ones: what the convergence table
    /// measures nearest to it.
    pub accuracy_warning: Option<String>,
}

impl Choice {
    /// One line for logs and diagnostics.
    pub fn describe(&self) -> String {
        let tried: Vec<String> = self
            .trials
            .iter()
            .map(|(dp, f)| format!("{:.4} m: {f:.2}", dp))
            .collect();
        let accuracy = match (&self.held_by_accuracy, &self.accuracy_warning) {
            (Some(_), _) => "; coarser spacings not tried: not accurate (convergence table)",
            (_, Some(_)) => "; coarser than the accurate spacings (convergence table)",
            _ => "",
        };
        format!(
            "dp {:.4} m, trial real-time factor {:.2}{} (target {:.2}; tried {}){accuracy}",
            self.particle_spacing,
            self.realtime_factor,
            if self.met {
                ""
            } else {
                ", below the target even at the coarsest spacing"
            },
            self.target_factor,
            tried.join(", ")
        )
    }
}

/// Candidate spacings from the coarsest to `finest`, a factor 1.25 apart.
pub fn candidates(finest: f64, coarsest: f64) -> Vec<f64> {
    let mut v = vec![];
    let mut dp = finest;
    while dp < coarsest * (1.0 + 1e-9) {
        v.push(dp);
        dp *= 1.25;
    }
    v.reverse();
    v
}

impl AutoResolutionCfg {
    /// The settings' own checks, before any trial: each bad value named with where it came from.
    pub fn check(&self, cfg: &Loaded) -> anyhow::Result<()> {
        let key = "realtime.auto_resolution";
        for (name, v, what) in [
            ("trial_s", self.trial_s, "simulated seconds each trial runs"),
            (
                "target_factor",
                self.target_factor,
                "real-time factor a trial must reach, e.g. 1.25",
            ),
        ] {
            if !(v.is_finite() && v > 0.0) {
                anyhow::bail!(
                    "{}: {key}.{name}: must be a positive number ({what}), got {v}",
                    cfg.source_of(&format!("{key}.{name}"))
                );
            }
        }
        let finest = cfg.config.particle_spacing;
        if !(self.max_spacing.is_finite() && self.max_spacing >= 0.0)
            || (self.max_spacing > 0.0 && self.max_spacing < finest)
        {
            anyhow::bail!(
                "{}: {key}.max_spacing: must be 0 (4 × particle_spacing) or at least particle_spacing ({finest} m, the finest spacing tried), got {}",
                cfg.source_of(&format!("{key}.max_spacing")),
                self.max_spacing
            );
        }
        Ok(())
    }
}

/// Chooses the spacing (see the module docs). `None` when `stop` was set during the trials (SIGINT or
/// SIGTERM): the caller stops as cleanly as it would have later.
pub fn choose(
    cfg: &Loaded,
    auto: &AutoResolutionCfg,
    stop: &AtomicBool,
) -> anyhow::Result<Option<Choice>> {
    let base: SimParams = cfg.sim_params()?;
    auto.check(cfg)?;
    let asked = if auto.max_spacing > 0.0 {
        auto.max_spacing
    } else {
        4.0 * base.particle_spacing
    };
    let (fill, finest) = (base.fill.height, base.particle_spacing);
    let accuracy = crate::accuracy::Accuracy::for_case(&base);
    let accurate = accuracy.coarsest_spacing(fill);
    let what = format!(
        "{} in {}D",
        crate::accuracy::setting_of(&base),
        base.dimension
    );
    let floor = accurate.unwrap_or(finest).max(finest);
    let (coarsest, held_by_accuracy) = if auto.allow_inaccurate || floor >= asked * (1.0 - 1e-9) {
        (asked, None)
    } else {
        let why = match (accurate, accuracy.per_depth) {
            (Some(_), Some(n)) => format!(
                "spacings coarser than {floor:.4} m not tried: the manual's convergence table measures the first sloshing mode's period within 1 % and a damping ratio of at most 0.005 with {what} only from {n:.0} particles per depth ({:.4} m for this {fill} m fill); realtime.auto_resolution.allow_inaccurate: true tries them",
                fill / n
            ),
            _ => format!(
                "no spacing coarser than particle_spacing ({finest} m) tried: the manual's convergence table measures no spacing of {what} with the first sloshing mode's period within 1 % and a damping ratio of at most 0.005; realtime.auto_resolution.allow_inaccurate: true tries coarser ones"
            ),
        };
        (floor, Some(why))
    };
    let motion = crate::motion_source::build(cfg)?;
    let mut trials = vec![];
    let mut skipped = vec![];
    let mut best: Option<(f64, f64)> = None;
    for dp in candidates(base.particle_spacing, coarsest) {
        let mut p = base.clone();
        p.particle_spacing = dp;
        if let Err(e) = p.validate() {
            skipped.push((dp, e.to_string()));
            continue;
        }
        if stop.load(Ordering::Relaxed) {
            return Ok(None);
        }
        let mut sim = sph::build(p)?;
        let t = auto.trial_s.min(motion.end_time());
        let start = Instant::now();
        // In slices, so that a signal stops the trials within a moment (advance_to enters the thread
        // pool once per call; a slice is many steps).
        while sim.time() < t {
            if stop.load(Ordering::Relaxed) {
                return Ok(None);
            }
            sim.advance_to(motion.as_ref(), (sim.time() + 0.02).min(t))?;
        }
        let rtf = sim.time() / start.elapsed().as_secs_f64();
        trials.push((dp, rtf));
        if rtf >= auto.target_factor {
            best = Some((dp, rtf));
        } else {
            break;
        }
    }
    let Some(&(coarse_dp, coarse_rtf)) = trials.first() else {
        let why = skipped
            .last()
            .map_or(String::new(), |(dp, e)| format!(" (at {dp:.4} m: {e})"));
        anyhow::bail!("realtime.auto_resolution: no valid particle spacing between particle_spacing and max_spacing{why}");
    };
    let (particle_spacing, realtime_factor, met) = match best {
        Some((dp, rtf)) => (dp, rtf, true),
        None => (coarse_dp, coarse_rtf, false),
    };
    let accuracy_warning = (particle_spacing > floor * (1.0 + 1e-9))
        .then(|| accuracy.nearest(fill, particle_spacing))
        .flatten()
        .map(|m| {
            format!(
                "dp {particle_spacing:.4} m ({:.0} particles per depth) is coarser than the spacings the manual's convergence table measures accurate with {what}; nearest to it the table measures the first sloshing mode's {}: expect errors of that size",
                fill / particle_spacing,
                m.describe()
            )
        });
    Ok(Some(Choice {
        particle_spacing,
        realtime_factor,
        trials,
        met,
        target_factor: auto.target_factor,
        skipped,
        held_by_accuracy,
        accuracy_warning,
    }))
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn candidates_run_from_coarse_to_fine() {
        let c = candidates(0.008, 0.02);
        assert_eq!(c.len(), 5);
        assert!((c[4] - 0.008).abs() < 1e-12);
        assert!(c.windows(2).all(|w| w[0] > w[1]));
        assert!(c[0] <= 0.02);
    }

    #[test]
    fn the_finest_spacing_that_keeps_the_target_is_chosen() {
        let text = "slosh:\n  ros__parameters:\n    dimension: 2\n    tank: {length: 0.8, breadth: 0.25, height: 0.6}\n    fill_height: 0.19\n    particle_spacing: 0.01\n    solver: {scheme: dfsph}\n";
        let cfg = crate::config::from_str(text, "test", None, &[]).unwrap();
        let auto = AutoResolutionCfg {
            enabled: true,
            max_spacing: 0.04,
            trial_s: 0.1,
            target_factor: 1.0,
            allow_inaccurate: true,
        };
        let c = choose(&cfg, &auto, &AtomicBool::new(false))
            .unwrap()
            .unwrap();
        // Trials go from coarse to fine and stop at the first that misses the target; the choice is the last
        // that met it (or the coarsest).
        assert!(!c.trials.is_empty());
        assert!(c.trials.windows(2).all(|w| w[0].0 > w[1].0));
        let passing: Vec<_> = c.trials.iter().filter(|t| t.1 >= 1.0).collect();
        if c.met {
            assert_eq!(passing.last().unwrap().0, c.particle_spacing);
            assert!(c.realtime_factor >= 1.0);
        } else {
            assert_eq!(c.particle_spacing, c.trials[0].0);
        }
        assert!(c.describe().contains("trial real-time factor"));
        assert!(c.describe().contains("(target 1.00;"));
        // Spacings coarser than the tank allows are listed as left out, not silently dropped.
        let coarse = AutoResolutionCfg {
            max_spacing: 0.5,
            ..auto
        };
        let c = choose(&cfg, &coarse, &AtomicBool::new(false))
            .unwrap()
            .unwrap();
        assert!(!c.skipped.is_empty() && c.skipped.iter().all(|(dp, _)| *dp > c.trials[0].0));
        // A signal before (or during) the trials ends them with no choice.
        assert_eq!(choose(&cfg, &auto, &AtomicBool::new(true)).unwrap(), None);
        // Coarser than the convergence table's accurate spacings (the shipped incompressible scheme has
        // none), the choice says what the table measures there.
        let c = choose(&cfg, &auto, &AtomicBool::new(false))
            .unwrap()
            .unwrap();
        assert_eq!(c.held_by_accuracy, None);
        if c.particle_spacing > 0.01 {
            let w = c.accuracy_warning.as_deref().expect("a warning");
            assert!(w.contains("period") && w.contains("damping ratio"), "{w}");
        }
    }

    /// By default the trials go no coarser than the coarsest spacing the convergence table measures
    /// accurate for the case's scheme, and say so.
    #[test]
    fn the_trials_keep_to_accurate_spacings_unless_told_otherwise() {
        let case = |extra: &str| {
            let text = format!("slosh:\n  ros__parameters:\n    dimension: 2\n    tank: {{length: 0.8, breadth: 0.25, height: 0.6}}\n    fill_height: 0.19\n    particle_spacing: 0.005\n    solver: {{scheme: dfsph{extra}}}\n");
            crate::config::from_str(&text, "test", None, &[]).unwrap()
        };
        let auto = AutoResolutionCfg {
            enabled: true,
            max_spacing: 0.02,
            trial_s: 0.02,
            target_factor: 1e-6,
            allow_inaccurate: false,
        };
        let never = AtomicBool::new(false);
        // The shipped settings: no spacing passes, so only particle_spacing is tried.
        let c = choose(&case(""), &auto, &never).unwrap().unwrap();
        assert_eq!(c.trials.len(), 1);
        assert_eq!(c.particle_spacing, 0.005);
        let why = c.held_by_accuracy.as_deref().expect("a reason");
        assert!(
            why.contains("no spacing coarser than particle_spacing")
                && why.contains("allow_inaccurate"),
            "{why}"
        );
        assert!(c.describe().contains("not accurate"), "{}", c.describe());
        // Corrected gradients, Wendland kernel, no artificial viscosity: accurate from about 24 particles per
        // depth, so the trials stop at the candidate spacings up to 0.19 m / 24.
        let corrected = case(
            ", kernel: wendland, artificial_viscosity: {alpha: 0.0}, dfsph: {kernel_correction: true}",
        );
        let c = choose(&corrected, &auto, &never).unwrap().unwrap();
        let floor = crate::accuracy::Accuracy::for_case(&corrected.sim_params().unwrap())
            .coarsest_spacing(0.19)
            .unwrap();
        assert!(c.trials.len() >= 2, "{c:?}");
        assert!(
            c.trials.iter().all(|t| t.0 <= floor * (1.0 + 1e-9)),
            "{c:?}"
        );
        assert!(c.held_by_accuracy.is_some() && c.accuracy_warning.is_none());
        // Allowed to, they start at max_spacing, and a coarse choice carries the table's figures.
        // (A target no trial meets: the coarsest is chosen.)
        let loose = AutoResolutionCfg {
            allow_inaccurate: true,
            target_factor: 1e6,
            ..auto
        };
        let c = choose(&case(""), &loose, &never).unwrap().unwrap();
        assert_eq!(c.particle_spacing, c.trials[0].0);
        assert!(c.particle_spacing > 0.015, "{c:?}");
        let w = c.accuracy_warning.as_deref().expect("a warning");
        assert!(
            w.contains("particles per depth") && w.contains("expect errors"),
            "{w}"
        );
    }

    #[test]
    fn bad_settings_are_named_before_any_trial() {
        let text = "slosh:\n  ros__parameters:\n    dimension: 2\n    tank: {length: 0.8, breadth: 0.25, height: 0.6}\n    fill_height: 0.19\n    particle_spacing: 0.01\n";
        let msg = |over: &[&str]| {
            let o: Vec<String> = over.iter().map(|s| s.to_string()).collect();
            let cfg = crate::config::from_str(text, "case.yaml", None, &o).unwrap();
            let auto = cfg.config.realtime.auto_resolution;
            auto.check(&cfg).unwrap_err().to_string()
        };
        let m = msg(&["realtime.auto_resolution.trial_s=-1"]);
        assert!(
            m.contains("realtime.auto_resolution.trial_s: must be a positive number")
                && m.contains("got -1"),
            "{m}"
        );
        let m = msg(&["realtime.auto_resolution.target_factor=0"]);
        assert!(m.contains("target_factor") && m.contains("got 0"), "{m}");
        let m = msg(&["realtime.auto_resolution.max_spacing=0.005"]);
        assert!(
            m.contains("max_spacing") && m.contains("at least particle_spacing (0.01 m"),
            "{m}"
        );
    }
}
