//! Automatic resolution for real time: times a short trial of the case at candidate particle spacings, from
//! the coarsest up, and keeps the finest whose measured real-time factor has the requested margin. The trial
//! runs the config's own `motion.*` (so it should resemble the motion expected live: a tank at rest steps
//! faster than a sloshing one).

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
}

impl Choice {
    /// One line for logs and diagnostics.
    pub fn describe(&self) -> String {
        let tried: Vec<String> = self
            .trials
            .iter()
            .map(|(dp, f)| format!("{:.4} m: {f:.2}", dp))
            .collect();
        format!(
            "dp {:.4} m, trial real-time factor {:.2}{} (target {:.2}; tried {})",
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
    let coarsest = if auto.max_spacing > 0.0 {
        auto.max_spacing
    } else {
        4.0 * base.particle_spacing
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
    Ok(Some(Choice {
        particle_spacing,
        realtime_factor,
        trials,
        met,
        target_factor: auto.target_factor,
        skipped,
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
