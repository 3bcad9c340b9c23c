//! A frame-time budget (`FrameSettings::budget`): the renderer moves the generated lights'
//! radius each frame so that the GPU time of a frame stays within the budget at the largest
//! radius that fits, which is the smallest error (the lab's fronts: with or without a far
//! field, a longer radius sums more light exactly). Engines scale resolution to a budget;
//! this scales the lights.
//!
//! The controller sees a frame's GPU time one or two frames after it was submitted
//! (timestamps are read back without waiting). It steers by the GPU time of the newest
//! finished frame drawn with the radius it chose last, so a change is judged by its own
//! effect and never by a frame that was already under way: that lag is what makes naive
//! controllers oscillate. The cost model is the light loop's: the lights a point
//! sees grow with the volume of their spheres, so the step is the cube root of the ratio
//! of the target to the measured time, limited to a factor of 1.5 either way. Times
//! within a band around the target leave the radius alone, so noise does not move it.

/// The time a frame aims at, as a fraction of the budget: the head room frame-to-frame
/// variation (camera, animation, noise) has before a frame goes over.
pub const BUDGET_TARGET: f64 = 0.85;

/// The band of measured times, as fractions of the budget, in which the radius stays.
pub const BUDGET_HOLD: (f64, f64) = (0.75, 0.95);

/// The most one step may scale the radius by (and the least, its inverse).
pub const BUDGET_MAX_STEP: f64 = 1.5;

/// The smallest radius the controller goes to, as a fraction of the asked one.
pub const BUDGET_MIN_RADIUS_FRACTION: f32 = 1e-3;

/// The radius chosen for a budget, frame after frame.
#[derive(Debug, Clone, PartialEq)]
pub struct BudgetController {
    /// The radius the next frame draws with.
    radius: f32,
    /// The first frame drawn with `radius`: older frames' times do not judge it.
    since_frame: u64,
}

impl BudgetController {
    /// Starting at `radius` (the asked radius: the budget only ever shortens it) from
    /// frame `frame` on.
    pub fn new(radius: f32, frame: u64) -> Self {
        Self {
            radius,
            since_frame: frame,
        }
    }

    /// The radius frames draw with now.
    pub fn radius(&self) -> f32 {
        self.radius
    }

    /// The radius for frame `next_frame`, given the budget, the asked radius (the most it
    /// may be) and the newest finished frame's number and GPU time, if any.
    pub fn next_radius(
        &mut self,
        budget_ms: f64,
        asked_radius: f32,
        next_frame: u64,
        finished: Option<(u64, f64)>,
    ) -> f32 {
        let largest = asked_radius;
        let smallest = asked_radius * BUDGET_MIN_RADIUS_FRACTION;
        self.radius = self.radius.clamp(smallest, largest);
        let Some((frame, measured_ms)) = finished else {
            return self.radius;
        };
        // A frame drawn before the last change, or no usable time: nothing to learn.
        let usable = |ms: f64| ms.is_finite() && ms > 0.0;
        if frame < self.since_frame || !usable(measured_ms) || !usable(budget_ms) {
            return self.radius;
        }
        let load = measured_ms / budget_ms;
        if load >= BUDGET_HOLD.0 && load <= BUDGET_HOLD.1 {
            return self.radius;
        }
        let step = (BUDGET_TARGET / load)
            .cbrt()
            .clamp(1.0 / BUDGET_MAX_STEP, BUDGET_MAX_STEP);
        let radius =
            (f64::from(self.radius) * step).clamp(f64::from(smallest), f64::from(largest)) as f32;
        if radius != self.radius {
            self.radius = radius;
            self.since_frame = next_frame;
        }
        self.radius
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scripted frame's GPU time: a fixed part plus the light loop, which grows with the
    /// light count and the cube of the radius and with how much of the scene the camera
    /// sees (`view`), with 3% noise from a fixed sequence.
    fn frame_ms(lights: f64, radius: f64, view: f64, frame: u64) -> f64 {
        let noise = 1.0 + 0.03 * (((frame * 2_654_435_761) % 1000) as f64 / 500.0 - 1.0);
        (1.5 + 2.0e-5 * lights * radius.powi(3) * view) * noise
    }

    /// Frames through a script: (frames, lights, view) segments, the GPU time of frame n
    /// known from frame n + 2 on. Returns each frame's time and radius.
    fn run(budget: f64, asked: f32, script: &[(u64, f64, f64)]) -> Vec<(f64, f32)> {
        let mut controller = BudgetController::new(asked, 1);
        let mut history: Vec<(f64, f32)> = Vec::new();
        let mut frame = 1u64;
        for &(frames, lights, view) in script {
            for _ in 0..frames {
                let finished = (frame > 2).then(|| (frame - 2, history[(frame - 3) as usize].0));
                let radius = controller.next_radius(budget, asked, frame, finished);
                history.push((frame_ms(lights, f64::from(radius), view, frame), radius));
                frame += 1;
            }
        }
        history
    }

    #[test]
    fn a_scripted_walk_from_a_thousand_to_a_million_lights_stays_within_the_budget() {
        // Light counts and views change every 120 frames (2 s at 60 Hz).
        let script = [
            (120, 1e3, 1.0),
            (120, 1e4, 0.6),
            (120, 1e5, 1.3),
            (120, 1e6, 0.8),
            (120, 1e6, 1.6),
            (120, 1e5, 0.5),
            (120, 1e3, 1.0),
        ];
        let history = run(8.0, 2.0, &script);
        // Each change of load takes a few frames to answer; the rest must fit.
        let settling = 12;
        let mut counted = 0;
        let mut within = 0;
        for (segment, &(frames, ..)) in script.iter().enumerate() {
            let start = segment * frames as usize;
            for &(ms, _) in &history[start + settling..start + frames as usize] {
                counted += 1;
                within += usize::from(ms <= 8.0);
            }
        }
        assert!(
            within * 100 >= counted * 95,
            "{within} of {counted} settled frames within 8 ms"
        );
        // Where the asked radius fits (1,000 lights), it is kept.
        assert_eq!(history[119].1, 2.0);
        assert_eq!(history.last().map(|h| h.1), Some(2.0));
        // At a million lights seen widely it went far down.
        assert!(history[599].1 < 0.75, "radius {}", history[599].1);
    }

    #[test]
    fn a_steady_load_settles_without_oscillating() {
        let history = run(8.0, 5.0, &[(600, 2e5, 1.0)]);
        let settled = &history[60..];
        let changes = settled.windows(2).filter(|w| w[0].1 != w[1].1).count();
        assert!(
            changes <= 2,
            "{changes} radius changes in 540 frames of a steady load"
        );
        let (ms, radius) = settled[settled.len() - 1];
        assert!(
            ms <= 8.0 && ms >= 8.0 * BUDGET_HOLD.0 * 0.9,
            "settled at {ms:.2} ms (radius {radius})"
        );
    }

    #[test]
    fn old_frames_do_not_judge_a_new_radius() {
        let mut controller = BudgetController::new(2.0, 1);
        // Frame 1 took four times the budget: the radius shrinks from frame 3 on.
        let shrunk = controller.next_radius(8.0, 2.0, 3, Some((1, 32.0)));
        assert!(shrunk < 2.0);
        // Frame 2 was drawn with the old radius: its time says nothing of the new one.
        assert_eq!(controller.next_radius(8.0, 2.0, 4, Some((2, 32.0))), shrunk);
        // Frame 3's does.
        assert!(controller.next_radius(8.0, 2.0, 5, Some((3, 30.0))) < shrunk);
        // No time, an unusable time or budget: the radius stays.
        let radius = controller.radius();
        assert_eq!(controller.next_radius(8.0, 2.0, 6, None), radius);
        assert_eq!(
            controller.next_radius(8.0, 2.0, 7, Some((6, f64::NAN))),
            radius
        );
        assert_eq!(controller.next_radius(0.0, 2.0, 8, Some((7, 3.0))), radius);
        // Never beyond the asked radius, never below its smallest fraction.
        let mut fast = BudgetController::new(1.0, 1);
        for frame in 2..50 {
            fast.next_radius(8.0, 1.0, frame, Some((frame - 1, 0.1)));
        }
        assert_eq!(fast.radius(), 1.0);
        let mut slow = BudgetController::new(1.0, 1);
        for frame in 2..200 {
            slow.next_radius(8.0, 1.0, frame, Some((frame - 1, 1e6)));
        }
        assert_eq!(slow.radius(), BUDGET_MIN_RADIUS_FRACTION);
    }
}
