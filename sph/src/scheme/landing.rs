//! Landing a step on a given time (an output time, the end of the motion) without leaving a sliver of a
//! step for after: a step much shorter than the flow's is wasted work at best, and in the incompressible
//! scheme it corrects the density error it starts with within that sliver and flings particles. Both
//! schemes land this way (cutting the step that would pass the time instead leaves steps of 1e-7 s, which
//! `min_dt_s` would report).

/// The step to take when the flow allows `dt` and a time to land on is `room` ahead: `room` itself when
/// it is within one step, half of it when within two (so no sliver is left for the step after), else `dt`.
pub fn landing_step(dt: f64, room: f64) -> f64 {
    // A relative margin, so that 0.02 s of 5 ms steps is four steps, not five.
    let steps = (room / dt * (1.0 - 1e-9)).ceil();
    if steps <= 1.0 {
        room
    } else if steps <= 2.0 {
        0.5 * room
    } else {
        dt
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn steps_land_without_a_sliver() {
        // Far from the landing time: the flow's step.
        assert_eq!(landing_step(0.005, 0.02), 0.005);
        assert_eq!(landing_step(0.005, 0.0151), 0.005);
        // Within two steps: half the rest each, never a sliver after.
        assert_eq!(landing_step(0.005, 0.0099), 0.00495);
        assert_eq!(landing_step(0.005, 0.0051), 0.00255);
        // Within one step (four 5 ms steps fill 20 ms exactly, whatever the rounding): the rest.
        assert_eq!(
            landing_step(0.005, 0.005 * (1.0 + 1e-12)),
            0.005 * (1.0 + 1e-12)
        );
        assert_eq!(landing_step(0.005, 0.004), 0.004);
    }
}
