//! The node's services: `~/reset` starts the liquid again at rest, `~/pause` freezes the simulation, and the
//! rcl_interfaces parameter services read the effective parameters and change the few live settings.

use super::LiveNode;
use ros2_client::ros2::LogLevel;
use slosh_msgs::std_srvs::{SetBoolResponse, TriggerResponse};

impl LiveNode<'_> {
    /// Answers every request waiting.
    pub(super) fn serve(&mut self) -> anyhow::Result<()> {
        while let Ok(Some((id, _))) = self.ends.srv.reset.receive_request() {
            let message = self.reset()?;
            self.log(LogLevel::Info, &format!("~/reset: {message}"));
            let success = true;
            let _ = self
                .ends
                .srv
                .reset
                .send_response(id, TriggerResponse { success, message });
        }
        while let Ok(Some((id, req))) = self.ends.srv.pause.receive_request() {
            let message = self.pause(req.data);
            self.log(LogLevel::Info, &format!("~/pause: {message}"));
            let success = true;
            let _ = self
                .ends
                .srv
                .pause
                .send_response(id, SetBoolResponse { success, message });
        }
        // A parameter change applies at once: the next output and cloud are placed on the new rates' grids.
        let before = self.live;
        let name = self.full_name.clone();
        let ends = &mut self.ends;
        let (node, logger) = (&ends.node, &self.logger);
        ends.srv
            .parameters
            .serve(&mut self.table, &mut self.live, &name, |m| {
                logger.log(node, LogLevel::Info, m)
            })?;
        if self.live != before {
            let t = self.sim.time();
            self.outputs.times.set_rate(self.live.output_rate_hz, t);
            self.clouds.set_rate(self.live.particles_rate_hz, t);
        }
        Ok(())
    }

    /// `~/reset`: the liquid at rest again, the next motion sample taken as t = 0.
    fn reset(&mut self) -> anyhow::Result<String> {
        self.sim = sph::build(self.params.clone())?;
        self.intake.motion = self.fresh_motion();
        self.intake.newest_stamp = None;
        self.outputs.restart();
        self.clouds.restart();
        self.intake.rebase = self.intake.t0.is_some();
        Ok("liquid reset to rest; the next motion sample is t = 0".to_string())
    }

    /// `~/pause` with `data`: pauses, or resumes from the current input without catching up on the paused
    /// stretch.
    fn pause(&mut self, data: bool) -> String {
        let t = self.sim.time();
        if data == self.paused {
            format!("already {}", if self.paused { "paused" } else { "running" })
        } else if data {
            self.paused = true;
            format!("paused at t = {t:.4} s")
        } else {
            self.paused = false;
            self.intake.motion = self.fresh_motion();
            self.intake.newest_stamp = None;
            self.intake.rebase = self.intake.t0.is_some();
            format!("resumed at t = {t:.4} s")
        }
    }
}
