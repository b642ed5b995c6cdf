//! Real-time accounting of the node, as plain logic over times so that tests need no clock: the real-time
//! factor over a sliding window, overruns (the simulation falling behind the newest input by more than a
//! margin), and the age of the input.

use std::collections::VecDeque;

/// Seconds of wall time the real-time factor is averaged over.
const WINDOW_S: f64 = 5.0;

#[derive(Debug, Clone)]
pub struct Pacing {
    /// (wall s, simulated s) pairs within the window.
    history: VecDeque<(f64, f64)>,
    /// s the simulation may lag behind the newest input before it counts as an overrun.
    margin: f64,
    behind: bool,
    /// Times the simulation fell behind (counted once per episode).
    pub overruns: u64,
    /// Wall time of the newest accepted input sample.
    last_input_wall: Option<f64>,
}

impl Pacing {
    pub fn new(margin: f64) -> Self {
        Self {
            history: VecDeque::new(),
            margin,
            behind: false,
            overruns: 0,
            last_input_wall: None,
        }
    }

    /// Records the simulation time reached at wall time `wall`, and the newest input time the simulation may
    /// reach. Returns true when an overrun starts (for a throttled warning).
    pub fn record(&mut self, wall: f64, sim: f64, input_until: f64) -> bool {
        self.history.push_back((wall, sim));
        while let Some(&(w, _)) = self.history.front() {
            if wall - w > WINDOW_S && self.history.len() > 2 {
                self.history.pop_front();
            } else {
                break;
            }
        }
        let lag = input_until - sim;
        if lag > self.margin {
            if !self.behind {
                self.behind = true;
                self.overruns += 1;
                return true;
            }
        } else {
            self.behind = false;
        }
        false
    }

    /// Notes that an input sample arrived at wall time `wall`.
    pub fn input(&mut self, wall: f64) {
        self.last_input_wall = Some(wall);
    }

    /// s since the last input (None before the first).
    pub fn input_age(&self, wall: f64) -> Option<f64> {
        self.last_input_wall.map(|w| wall - w)
    }

    /// Simulated seconds per wall second over the window (0 until two records).
    pub fn realtime_factor(&self) -> f64 {
        match (self.history.front(), self.history.back()) {
            (Some(&(w0, s0)), Some(&(w1, s1))) if w1 > w0 => (s1 - s0) / (w1 - w0),
            _ => 0.0,
        }
    }

    /// Whether the simulation is behind the input now.
    pub fn behind(&self) -> bool {
        self.behind
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn realtime_factor_over_the_window() {
        let mut p = Pacing::new(0.1);
        for i in 0..=100 {
            let wall = i as f64 * 0.1;
            p.record(wall, 0.5 * wall, 0.5 * wall);
        }
        assert!((p.realtime_factor() - 0.5).abs() < 1e-12);
        // Only the last 5 s count: speed up to 2x and the factor follows.
        for i in 101..=160 {
            let wall = i as f64 * 0.1;
            p.record(wall, 5.0 + 2.0 * (wall - 10.0), 100.0);
        }
        assert!(
            (p.realtime_factor() - 2.0).abs() < 1e-9,
            "{}",
            p.realtime_factor()
        );
    }

    #[test]
    fn overruns_count_episodes_not_steps() {
        let mut p = Pacing::new(0.1);
        assert!(!p.record(0.0, 0.0, 0.05));
        assert!(p.record(1.0, 0.5, 1.0)); // 0.5 s behind: an overrun starts
        assert!(!p.record(1.1, 0.6, 1.1)); // still behind: same episode
        assert!(p.behind());
        assert!(!p.record(1.2, 1.15, 1.2)); // caught up
        assert!(!p.behind());
        assert!(p.record(2.0, 1.5, 2.0)); // behind again
        assert_eq!(p.overruns, 2);
        assert_eq!(p.input_age(3.0), None);
        p.input(2.5);
        assert_eq!(p.input_age(3.0), Some(0.5));
    }
}
