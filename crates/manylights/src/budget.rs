//! A frame-time budget (`FrameSettings::budget`): the renderer moves the generated lights'
//! radius and, with a light-tree far field, the cut's slots each frame so that the GPU time
//! of a frame stays within the budget at the smallest error that fits (the lab's fronts).
//! Engines scale resolution to a budget; this scales the lights.
//!
//! The asked radius and slots are the most the budget gives. Without a far field the
//! radius is the only dial: a longer radius sums more light exactly. With the tree the
//! fronts rank the dials (H200, Sponza 1920x1080, `scripts/gpu-machine-far-radius.sh`,
//! docs/results/nvidia-h200/budget): at 1,000,000 lights, radius 0.05 to 0.25 m moves the
//! error by at most 0.012 and slots 64 to 512 by 0.085 (0.109 to 0.025) for about 4 ms; at
//! 100,000 the radius moves it by at most 0.007. So the budget gives up radius first, down to
//! [`BUDGET_FAR_RADIUS_FRACTION`] of the asked one, then slots, down to
//! [`BUDGET_MIN_FAR_SLOTS`], then the rest of the radius; and takes them back in the
//! opposite order. (The tree's tolerance is not a dial: at these counts the slots fill
//! before it binds; 0.1 against 1 at 192 slots measured 0.048 against 0.049, 0.5 ms slower.)
//!
//! The controller sees a frame's GPU time one or two frames after it was submitted
//! (timestamps are read back without waiting). It steers by the GPU time of the newest
//! finished frame drawn with the choice it made last, so a change is judged by its own
//! effect and never by a frame that was already under way: that lag is what makes naive
//! controllers oscillate. The cost models are the light loop's: the lights a point sees
//! grow with the volume of their spheres, so a radius step is the cube root of the ratio of
//! the target to the measured time; the cut's cost grows with its slots, so a slots step is
//! that ratio itself (the far field being part of the frame, it under-corrects rather than
//! overshoots). Steps are limited to a factor of 1.5 either way, and times within a band
//! around the target leave everything alone, so noise moves nothing.

use manylights_lights::RadiusMode;

use crate::settings::FrameSettings;

/// The time a frame aims at, as a fraction of the budget: the head room frame-to-frame
/// variation (camera, animation, noise) has before a frame goes over.
pub const BUDGET_TARGET: f64 = 0.85;

/// The band of measured times, as fractions of the budget, in which nothing moves.
pub const BUDGET_HOLD: (f64, f64) = (0.75, 0.95);

/// The most one step may scale a dial by (and the least, its inverse).
pub const BUDGET_MAX_STEP: f64 = 1.5;

/// The smallest radius the controller goes to, as a fraction of the asked one.
pub const BUDGET_MIN_RADIUS_FRACTION: f32 = 1e-3;

/// With a tree far field, the radius (as a fraction of the asked one) the budget shortens
/// to before it takes slots: 2 m asked gives 0.1 m, the radius of Sponza's best fronts at
/// 1,000,000 lights (0.055 at 192 slots in 7.56 ms, where 0.05 m gave 0.061 in 7.65).
pub const BUDGET_FAR_RADIUS_FRACTION: f32 = 0.05;

/// The fewest slots the budget leaves a cut: the root and one split of it.
pub const BUDGET_MIN_FAR_SLOTS: u32 = 8;

/// What a budget chooses for a frame.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BudgetChoice {
    /// The generated lights' radius.
    pub radius: f32,
    /// With a tree far field: the most entries a cluster's cut holds.
    pub far_slots: Option<u32>,
    /// The newest frame judged was over the budget with every dial at its least: the
    /// budget is out of reach (a UI says so rather than leaving the user guessing).
    pub out_of_reach: bool,
}

impl BudgetChoice {
    /// `settings` with this choice's radius and, with a far field, its slots.
    pub fn applied_to(&self, settings: &FrameSettings) -> FrameSettings {
        let mut budgeted = settings.clone();
        budgeted.lights.radius = RadiusMode::Fixed(self.radius);
        if let Some(far) = (budgeted.pipeline.clustering_mut())
            .and_then(|clustering| clustering.far_field.as_mut())
        {
            far.slots = self.far_slots.unwrap_or(far.slots);
        }
        budgeted
    }
}

/// What the frame asks for: the most a budget gives.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BudgetAsk {
    pub radius: f32,
    /// The tree's slots when the frame has a tree far field.
    pub far_slots: Option<u32>,
}

/// The radius and slots chosen for a budget, frame after frame.
#[derive(Debug, Clone, PartialEq)]
pub struct BudgetController {
    /// What the next frame draws with.
    choice: BudgetChoice,
    /// The first frame drawn with `choice`: older frames' times do not judge it.
    since_frame: u64,
    /// With a far field, after a step that shortened the radius above the far field's: the
    /// load that asked for it and the share of it the step was to save.
    shortening: Option<(f64, f64)>,
}

/// One dial's range and the step it takes for a load ratio.
struct Dial {
    least: f64,
    most: f64,
    /// The exponent of the step: 1/3 for the radius (cost with the sphere's volume), 1
    /// for the slots.
    exponent: f64,
}

impl Dial {
    /// `value` moved by the step for `ratio` (target over measured time), within range.
    fn step(&self, value: f64, ratio: f64) -> f64 {
        let step = ratio
            .powf(self.exponent)
            .clamp(1.0 / BUDGET_MAX_STEP, BUDGET_MAX_STEP);
        f64::from((value * step).clamp(self.least, self.most) as f32)
    }
}

impl BudgetController {
    /// Starting at what the frame asks for (the budget only ever gives less) from frame
    /// `frame` on.
    pub fn new(ask: BudgetAsk, frame: u64) -> Self {
        Self {
            choice: BudgetChoice {
                radius: ask.radius,
                far_slots: ask.far_slots,
                out_of_reach: false,
            },
            since_frame: frame,
            shortening: None,
        }
    }

    /// What frames draw with now.
    pub fn choice(&self) -> BudgetChoice {
        self.choice
    }

    /// The choice for frame `next_frame`, given the budget, what the frame asks for (the
    /// most it may be) and the newest finished frame's number and GPU time, if any.
    pub fn next(
        &mut self,
        budget_ms: f64,
        ask: BudgetAsk,
        next_frame: u64,
        finished: Option<(u64, f64)>,
    ) -> BudgetChoice {
        // Radii are f32s (what frames draw with), so a radius clamped to a bound equals
        // it and the next step sees it there.
        let asked_radius = f64::from(ask.radius);
        let smallest_radius = f64::from(ask.radius * BUDGET_MIN_RADIUS_FRACTION);
        // The radius's two ranges: the one given up before the slots (above `far_radius`)
        // and the one after.
        let far_radius = f64::from(ask.radius * BUDGET_FAR_RADIUS_FRACTION);
        let mut radius = f64::from(self.choice.radius).clamp(smallest_radius, asked_radius);
        let mut slots = match (ask.far_slots, self.choice.far_slots) {
            (Some(asked), Some(chosen)) => {
                Some(chosen.clamp(BUDGET_MIN_FAR_SLOTS.min(asked), asked))
            }
            // A far field turned on (or its slots asked anew): from what is asked.
            (asked, _) => asked,
        };
        let choice = |radius: f64, slots: Option<u32>, out_of_reach: bool| BudgetChoice {
            radius: radius as f32,
            far_slots: slots,
            out_of_reach,
        };
        self.choice = choice(radius, slots, self.choice.out_of_reach);
        let Some((frame, measured_ms)) = finished else {
            return self.choice;
        };
        // A frame drawn before the last change, or no usable time: nothing to learn.
        let usable = |ms: f64| ms.is_finite() && ms > 0.0;
        if frame < self.since_frame || !usable(measured_ms) || !usable(budget_ms) {
            return self.choice;
        }
        let load = measured_ms / budget_ms;
        let shortening = self.shortening.take();
        if load >= BUDGET_HOLD.0 && load <= BUDGET_HOLD.1 {
            self.choice.out_of_reach = false;
            return self.choice;
        }
        let ratio = BUDGET_TARGET / load;
        let before = (radius, slots);
        // Slots are chosen exactly when they are asked for.
        match (slots, ask.far_slots) {
            (Some(current), Some(asked_slots)) => {
                let step = LoadStep {
                    load,
                    ratio,
                    shortening,
                };
                let radii = RadiusRange {
                    smallest: smallest_radius,
                    far: far_radius,
                    asked: asked_radius,
                };
                let stepped = self.step_with_slots(radii, step, radius, current, asked_slots);
                (radius, slots) = (stepped.0, Some(stepped.1));
            }
            _ => radius = radius_dial(smallest_radius, asked_radius).step(radius, ratio),
        }
        let out_of_reach = ratio < 1.0 && before == (radius, slots);
        if before != (radius, slots) {
            self.since_frame = next_frame;
        }
        self.choice = choice(radius, slots, out_of_reach);
        self.choice
    }
}

/// The radius's range under a tree far field: the smallest it goes to, the far field's
/// radius (below which it is given up after the slots) and the asked one.
#[derive(Debug, Clone, Copy)]
struct RadiusRange {
    smallest: f64,
    far: f64,
    asked: f64,
}

/// The frame the controller steps from: its load (measured over budget time), the ratio
/// it steps by (target over load) and the last shortening of the upper radius (the load
/// it was made at and the share of the loop it was to save).
#[derive(Debug, Clone, Copy)]
struct LoadStep {
    load: f64,
    ratio: f64,
    shortening: Option<(f64, f64)>,
}

/// A radius dial between `least` and `most` (its cost grows with the sphere's volume).
fn radius_dial(least: f64, most: f64) -> Dial {
    Dial {
        least,
        most,
        exponent: 1.0 / 3.0,
    }
}

impl BudgetController {
    /// One step of the radius and the slots (`current` of `asked_slots`) with a tree far
    /// field: over the budget, the upper radius, then the slots, then the lower radius;
    /// under, the same in the opposite order.
    fn step_with_slots(
        &mut self,
        radii: RadiusRange,
        step: LoadStep,
        mut radius: f64,
        current: u32,
        asked_slots: u32,
    ) -> (f64, u32) {
        let LoadStep {
            load,
            ratio,
            shortening,
        } = step;
        let least_slots = BUDGET_MIN_FAR_SLOTS.min(asked_slots);
        let slots_dial = Dial {
            least: f64::from(least_slots),
            most: f64::from(asked_slots),
            exponent: 1.0,
        };
        // Rounded away from the current count, so a step of less than one slot still
        // moves it.
        let stepped_slots = || {
            let next = slots_dial.step(f64::from(current), ratio);
            (if ratio < 1.0 {
                next.floor()
            } else {
                next.ceil()
            }) as u32
        };
        let upper = radius_dial(radii.far, radii.asked);
        let lower = radius_dial(radii.smallest, radii.far);
        if ratio < 1.0 {
            // The radius above the far field's is worth little, but where the near field
            // is a small share of the frame it saves little too: a step that saved under a
            // quarter of what it was to (the cube of the radius's step) shows the rest of
            // it would not fit either, and it goes at once, with a step of the slots.
            let spent =
                shortening.is_some_and(|(previous, saving)| load > previous * (1.0 - saving / 4.0));
            if radius > radii.far && !spent {
                let shortened = upper.step(radius, ratio);
                self.shortening = Some((load, 1.0 - (shortened / radius).powi(3)));
                (shortened, current)
            } else if radius > radii.far {
                (radii.far, stepped_slots())
            } else if current > least_slots {
                (radius, stepped_slots())
            } else {
                radius = lower.step(radius, ratio);
                (radius, current)
            }
        } else if radius < radii.far {
            (lower.step(radius, ratio), current)
        } else if current < asked_slots {
            (radius, stepped_slots())
        } else {
            (upper.step(radius, ratio), current)
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    /// A scripted frame's GPU time: a fixed part plus the light loop, which grows with the
    /// light count and the cube of the radius and with how much of the scene the camera
    /// sees (`view`), plus with a far field its tree (with the light count) and cut (with
    /// the slots it fills: where lights are few the tolerance stops it first), with 3%
    /// noise from a fixed sequence.
    fn frame_ms(lights: f64, choice: BudgetChoice, view: f64, frame: u64) -> f64 {
        let noise = 1.0 + 0.03 * (((frame * 2_654_435_761) % 1000) as f64 / 500.0 - 1.0);
        let near = 2.0e-5 * lights * f64::from(choice.radius).powi(3) * view;
        let far = choice.far_slots.map_or(0.0, |slots| {
            2.0e-6 * lights + 0.012 * f64::from(slots).min(lights / 100.0) * view
        });
        (1.5 + near + far) * noise
    }

    /// Frames through a script: (frames, lights, view) segments, the GPU time of frame n
    /// known from frame n + 2 on. Returns each frame's time and choice.
    fn run(budget: f64, ask: BudgetAsk, script: &[(u64, f64, f64)]) -> Vec<(f64, BudgetChoice)> {
        let mut controller = BudgetController::new(ask, 1);
        let mut history: Vec<(f64, BudgetChoice)> = Vec::new();
        let mut frame = 1u64;
        for &(frames, lights, view) in script {
            for _ in 0..frames {
                let finished = (frame > 2).then(|| (frame - 2, history[(frame - 3) as usize].0));
                let choice = controller.next(budget, ask, frame, finished);
                history.push((frame_ms(lights, choice, view, frame), choice));
                frame += 1;
            }
        }
        history
    }

    fn radius_only(radius: f32) -> BudgetAsk {
        BudgetAsk {
            radius,
            far_slots: None,
        }
    }

    /// Light counts and views that change every 120 frames (2 s at 60 Hz).
    const WALK: [(u64, f64, f64); 7] = [
        (120, 1e3, 1.0),
        (120, 1e4, 0.6),
        (120, 1e5, 1.3),
        (120, 1e6, 0.8),
        (120, 1e6, 1.6),
        (120, 1e5, 0.5),
        (120, 1e3, 1.0),
    ];

    /// The settled frames of a walk (each change of load takes a few frames to answer)
    /// within the budget, and how many were counted.
    fn settled_within(history: &[(f64, BudgetChoice)], budget: f64) -> (usize, usize) {
        let settling = 12;
        let mut counted = 0;
        let mut within = 0;
        for (segment, &(frames, ..)) in WALK.iter().enumerate() {
            let start = segment * frames as usize;
            for &(ms, _) in &history[start + settling..start + frames as usize] {
                counted += 1;
                within += usize::from(ms <= budget);
            }
        }
        (within, counted)
    }

    #[test]
    fn a_scripted_walk_from_a_thousand_to_a_million_lights_stays_within_the_budget() {
        let history = run(8.0, radius_only(2.0), &WALK);
        let (within, counted) = settled_within(&history, 8.0);
        assert!(
            within * 100 >= counted * 95,
            "{within} of {counted} settled frames within 8 ms"
        );
        // Where the asked radius fits (1,000 lights), it is kept.
        assert_eq!(history[119].1.radius, 2.0);
        assert_eq!(history.last().map(|h| h.1.radius), Some(2.0));
        // At a million lights seen widely it went far down.
        assert!(history[599].1.radius < 0.75, "{:?}", history[599].1);
    }

    #[test]
    fn with_a_far_field_the_radius_goes_before_the_slots_and_comes_back_after() {
        let ask = BudgetAsk {
            radius: 2.0,
            far_slots: Some(512),
        };
        let history = run(8.0, ask, &WALK);
        let (within, counted) = settled_within(&history, 8.0);
        assert!(
            within * 100 >= counted * 95,
            "{within} of {counted} settled frames within 8 ms"
        );
        let far_radius = 2.0 * BUDGET_FAR_RADIUS_FRACTION;
        let mut took_slots = false;
        for (frame, &(_, choice)) in history.iter().enumerate() {
            let slots = choice.far_slots.expect("slots");
            assert!(
                (BUDGET_MIN_FAR_SLOTS..=512).contains(&slots)
                    && choice.radius <= 2.0
                    && choice.radius >= 2.0 * BUDGET_MIN_RADIUS_FRACTION,
                "frame {frame}: {choice:?}"
            );
            // Slots are taken only once the radius is down to the far field's, and the
            // radius goes below that only once the slots are at their least.
            assert!(
                slots == 512 || choice.radius <= far_radius,
                "frame {frame}: slots taken at radius {}",
                choice.radius
            );
            assert!(
                choice.radius >= far_radius || slots == BUDGET_MIN_FAR_SLOTS,
                "frame {frame}: radius {} below the far field's with {slots} slots",
                choice.radius
            );
            took_slots |= slots < 512;
        }
        assert!(took_slots, "a million lights never took slots");
        // A thousand lights fit everything asked.
        assert_eq!(
            history.last().map(|h| h.1),
            Some(BudgetChoice {
                radius: 2.0,
                far_slots: Some(512),
                out_of_reach: false
            })
        );
    }

    #[test]
    fn a_radius_that_saves_nothing_goes_at_once() {
        // A million lights with a short radius: the near field is 0.5 of 10 ms, the cut's
        // 512 slots most of the rest, so shortening the radius cannot fit the budget.
        let ask = BudgetAsk {
            radius: 0.3,
            far_slots: Some(512),
        };
        let history = run(8.0, ask, &[(120, 1e6, 1.0)]);
        let first_slots = history
            .iter()
            .position(|(_, choice)| choice.far_slots != Some(512))
            .expect("the slots never moved");
        // Two radius steps, each judged two frames on, show it; cube-root steps all the
        // way down would take about 20 frames.
        assert!(
            first_slots <= 8,
            "the slots first moved at frame {first_slots}"
        );
        assert_eq!(
            history[first_slots].1.radius,
            0.3 * BUDGET_FAR_RADIUS_FRACTION
        );
        let (ms, choice) = history[history.len() - 1];
        assert!(ms <= 8.0, "settled at {ms:.2} ms ({choice:?})");
    }

    #[test]
    fn a_steady_load_settles_without_oscillating() {
        for ask in [
            radius_only(5.0),
            BudgetAsk {
                radius: 5.0,
                far_slots: Some(512),
            },
        ] {
            let history = run(8.0, ask, &[(600, 2e5, 1.0)]);
            let settled = &history[60..];
            let changes = settled.windows(2).filter(|w| w[0].1 != w[1].1).count();
            assert!(
                changes <= 2,
                "{ask:?}: {changes} changes in 540 frames of a steady load"
            );
            let (ms, choice) = settled[settled.len() - 1];
            assert!(
                ms <= 8.0 && ms >= 8.0 * BUDGET_HOLD.0 * 0.9,
                "{ask:?}: settled at {ms:.2} ms ({choice:?})"
            );
        }
    }

    #[test]
    fn old_frames_do_not_judge_a_new_choice() {
        let ask = radius_only(2.0);
        let mut controller = BudgetController::new(ask, 1);
        // Frame 1 took four times the budget: the radius shrinks from frame 3 on.
        let shrunk = controller.next(8.0, ask, 3, Some((1, 32.0))).radius;
        assert!(shrunk < 2.0);
        // Frame 2 was drawn with the old radius: its time says nothing of the new one.
        assert_eq!(controller.next(8.0, ask, 4, Some((2, 32.0))).radius, shrunk);
        // Frame 3's does.
        assert!(controller.next(8.0, ask, 5, Some((3, 30.0))).radius < shrunk);
        // No time, an unusable time or budget: nothing moves.
        let choice = controller.choice();
        assert_eq!(controller.next(8.0, ask, 6, None), choice);
        assert_eq!(controller.next(8.0, ask, 7, Some((6, f64::NAN))), choice);
        assert_eq!(controller.next(0.0, ask, 8, Some((7, 3.0))), choice);
    }

    #[test]
    fn the_dials_stay_within_what_is_asked_and_their_least() {
        for far_slots in [None, Some(64)] {
            let ask = BudgetAsk {
                radius: 1.0,
                far_slots,
            };
            let mut fast = BudgetController::new(ask, 1);
            for frame in 2..50 {
                fast.next(8.0, ask, frame, Some((frame - 1, 0.1)));
            }
            assert_eq!(
                fast.choice(),
                BudgetChoice {
                    radius: 1.0,
                    far_slots,
                    out_of_reach: false
                }
            );
            // A budget nothing fits: every dial at its least, and it says so.
            let mut slow = BudgetController::new(ask, 1);
            for frame in 2..400 {
                slow.next(8.0, ask, frame, Some((frame - 1, 1e6)));
            }
            assert_eq!(
                slow.choice(),
                BudgetChoice {
                    radius: BUDGET_MIN_RADIUS_FRACTION,
                    far_slots: far_slots.map(|_| BUDGET_MIN_FAR_SLOTS),
                    out_of_reach: true
                }
            );
            // A frame that fits again: no longer out of reach.
            assert!(!slow.next(8.0, ask, 400, Some((399, 7.0))).out_of_reach);
        }
        // Asked for fewer slots than the budget's least: the asked count is the least.
        let ask = BudgetAsk {
            radius: 1.0,
            far_slots: Some(4),
        };
        let mut few = BudgetController::new(ask, 1);
        for frame in 2..400 {
            few.next(8.0, ask, frame, Some((frame - 1, 1e6)));
        }
        assert_eq!(few.choice().far_slots, Some(4));
    }
}
