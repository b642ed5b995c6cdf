//! Automatic resolution for real time: times a short trial of the case at candidate particle spacings, from
//! the coarsest up, and keeps the finest whose measured real-time factor has the requested margin. The trial
//! runs the config's own `motion.*` (so it should resemble the motion expected live: a tank at rest steps
//! faster than a sloshing one).

use crate::config::Loaded;
use sph::params::SimParams;
use std::time::Instant;

/// What `realtime.auto_resolution.*` configures.
#[derive(Debug, Clone, Copy, serde::Deserialize)]
#[serde(deny_unknown_fields, default)]
pub struct AutoResolutionCfg {
    pub enabled: bool,
    /// Coarsest spacing tried, m (0: 4 × `particle_spacing`). `particle_spacing` is the finest.
    pub max_spacing: f64,
    /// Simulated seconds of each trial.
    pub trial_s: f64,
    /// Real-time factor a spacing must reach in its trial to be chosen.
    pub target_factor: f64,
}

impl Default for AutoResolutionCfg {
    fn default() -> Self {
        Self {
            enabled: false,
            max_spacing: 0.0,
            trial_s: 0.3,
            target_factor: 1.25,
        }
    }
}

/// The outcome: the spacing chosen, its measured real-time factor, and every trial (spacing, factor).
#[derive(Debug, Clone, PartialEq, serde::Serialize)]
pub struct Choice {
    pub particle_spacing: f64,
    pub realtime_factor: f64,
    pub trials: Vec<(f64, f64)>,
    /// The target was met (else the coarsest spacing is used anyway).
    pub met: bool,
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
            "dp {:.4} m, trial real-time factor {:.2}{} (tried {})",
            self.particle_spacing,
            self.realtime_factor,
            if self.met {
                ""
            } else {
                ", below the target even at the coarsest spacing"
            },
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

/// Chooses the spacing (see the module docs).
pub fn choose(cfg: &Loaded, auto: &AutoResolutionCfg) -> anyhow::Result<Choice> {
    let base: SimParams = cfg.sim_params()?;
    if !(auto.trial_s > 0.0 && auto.target_factor > 0.0) {
        anyhow::bail!("realtime.auto_resolution: trial_s and target_factor must be positive");
    }
    let coarsest = if auto.max_spacing > 0.0 {
        auto.max_spacing
    } else {
        4.0 * base.particle_spacing
    };
    if coarsest < base.particle_spacing {
        anyhow::bail!(
            "realtime.auto_resolution.max_spacing ({coarsest} m) is finer than particle_spacing ({} m)",
            base.particle_spacing
        );
    }
    let motion = crate::motion_source::build(cfg)?;
    let mut trials = vec![];
    let mut best: Option<(f64, f64)> = None;
    for dp in candidates(base.particle_spacing, coarsest) {
        let mut p = base.clone();
        p.particle_spacing = dp;
        if p.validate().is_err() {
            continue;
        }
        let mut sim = sph::build(p)?;
        let t = auto.trial_s.min(motion.end_time());
        let start = Instant::now();
        sim.advance_to(motion.as_ref(), t)?;
        let rtf = sim.time() / start.elapsed().as_secs_f64();
        trials.push((dp, rtf));
        if rtf >= auto.target_factor {
            best = Some((dp, rtf));
        } else {
            break;
        }
    }
    let Some(&(coarse_dp, coarse_rtf)) = trials.first() else {
        anyhow::bail!("realtime.auto_resolution: no valid particle spacing between particle_spacing and max_spacing");
    };
    Ok(match best {
        Some((dp, rtf)) => Choice {
            particle_spacing: dp,
            realtime_factor: rtf,
            trials,
            met: true,
        },
        None => Choice {
            particle_spacing: coarse_dp,
            realtime_factor: coarse_rtf,
            trials,
            met: false,
        },
    })
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
        let c = choose(&cfg, &auto).unwrap();
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
    }
}
