//! A sequence's misregistration budget: how much each effect of time adds to what the
//! display shows, found by running the sequence again without it.
//!
//! The effects are added in the order of [`Effect::ALL`] to a baseline without any of them
//! (no latency, a refresh at every frame, instant shutters, a display that shows each refresh
//! at once): each step is the
//! sequence with the effects up to it, the last the sequence as asked. A step's change is
//! what its effect adds after those before it, so the changes sum to the whole sequence's
//! misregistration less the baseline's, exactly. Misregistrations are lengths, not signed
//! sums, so an effect's change depends on the ones already there (two shifts in opposite
//! directions partly cancel): the order is part of the answer, and the budget says it.

use anyhow::Result;
use serde::Serialize;

use crate::geometry::shutter::Scanout;
use crate::io::plot::Figure;
use crate::measure::sequence::{Measuring, SequenceRun, run_sequence_labelled};
use crate::measure::sequence_files::{mean_of_frame_stats, over_time_figure};
use crate::measure::sequence_records::FrameRecord;
use crate::scene::Scene;
use crate::system::sequence::system_loop::SequenceOptions;

/// An effect of time on what the display shows.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
#[serde(rename_all = "snake_case")]
pub enum Effect {
    /// The frontal image's and the head estimate's age when shown (`latency_camera`,
    /// `latency_tracking`).
    Latency,
    /// The display holding each refresh's image until the next, looked at in between (frames
    /// sampled faster than, or between, the display's refreshes).
    Hold,
    /// The cameras' rows read before the last (`shutter = "rolling"`, `readout_ms`).
    Readout,
    /// The cameras' exposures (`exposure_ms`).
    Exposure,
    /// The display's rows lit in turn and held or flashed (`scanout`, `persistence_ms`).
    Scanout,
}

impl Effect {
    /// The order the budget adds them in.
    pub const ALL: [Effect; 5] = [
        Effect::Latency,
        Effect::Hold,
        Effect::Readout,
        Effect::Exposure,
        Effect::Scanout,
    ];

    pub fn label(self) -> &'static str {
        match self {
            Effect::Latency => "latency",
            Effect::Hold => "sample and hold",
            Effect::Readout => "readout skew",
            Effect::Exposure => "exposure blur",
            Effect::Scanout => "scan-out",
        }
    }

    /// Whether `scene` and `options` have this effect.
    fn present(self, scene: &Scene, options: &SequenceOptions) -> bool {
        let cameras = [scene.frontal.shutter, scene.back.shutter];
        match self {
            Effect::Latency => {
                options.timeline.latency_camera > 0.0 || options.timeline.latency_tracking > 0.0
            }
            Effect::Hold => {
                let t = options.timeline;
                // The timeline's own 1e-9 s: a frame at a refresh's instant is at it.
                (0..t.frames()).any(|k| t.times(k).display > t.times(k).refresh_time + 1e-9)
            }
            Effect::Readout => cameras.iter().any(|s| s.readout_s > 0.0),
            Effect::Exposure => cameras.iter().any(|s| s.exposure_s > 0.0),
            Effect::Scanout => scene.obstacle.scanout != Scanout::default(),
        }
    }

    /// Takes this effect out of `scene` and `options`.
    fn remove(self, scene: &mut Scene, options: &mut SequenceOptions) {
        let cameras = [&mut scene.frontal.shutter, &mut scene.back.shutter];
        match self {
            Effect::Latency => {
                options.timeline.latency_camera = 0.0;
                options.timeline.latency_tracking = 0.0;
            }
            // A refresh at every frame: each is looked at as it is shown.
            Effect::Hold => options.timeline.display_hz = options.timeline.fps,
            Effect::Readout => cameras.into_iter().for_each(|s| s.readout_s = 0.0),
            Effect::Exposure => cameras.into_iter().for_each(|s| s.exposure_s = 0.0),
            Effect::Scanout => scene.obstacle.scanout = Scanout::default(),
        }
    }
}

/// Whether the sequence of `scene` and `options` has any effect of time to split.
pub fn has_effects_of_time(scene: &Scene, options: &SequenceOptions) -> bool {
    Effect::ALL.iter().any(|e| e.present(scene, options))
}

/// One step of the budget: the sequence with the effects up to `added`.
#[derive(Clone, Debug)]
pub struct BudgetStep {
    /// The effect this step adds; `None`: the baseline, without any.
    pub added: Option<Effect>,
    /// Whether the sequence has the effect; if not, the step is the one before (not run
    /// again: the same sequence gives the same numbers).
    pub present: bool,
    /// The mean over frames of each frame's mean misregistration, arc-minutes.
    pub mean_arcmin: f64,
    /// The mean over frames of each frame's 95th percentile, arc-minutes.
    pub p95_arcmin: f64,
    /// The mean over frames of the share of display pixels measured, [0, 1].
    pub coverage: f64,
    /// The step's frames (their times and metrics), for the plot.
    pub records: Vec<FrameRecord>,
}

impl BudgetStep {
    fn of(added: Option<Effect>, present: bool, run: &SequenceRun) -> BudgetStep {
        let [mean_arcmin, p95_arcmin] = mean_of_frame_stats(run);
        let covered: Vec<f64> = run
            .records
            .iter()
            .filter_map(|r| r.metrics.map(|m| m.coverage))
            .collect();
        BudgetStep {
            added,
            present,
            mean_arcmin,
            p95_arcmin,
            coverage: covered.iter().sum::<f64>() / covered.len() as f64,
            records: run.records.clone(),
        }
    }

    pub fn label(&self) -> &'static str {
        self.added.map_or("none (no effect of time)", Effect::label)
    }
}

/// The budget: the baseline, then one step per effect of [`Effect::ALL`], the last the
/// sequence as asked.
#[derive(Clone, Debug)]
pub struct Budget {
    pub steps: Vec<BudgetStep>,
}

/// The budget of the sequence of `scene` and `options`, whose run as asked is `whole`
/// (measured with `how`): the steps without the effects after them are run again, each as
/// `how` says, with its progress labelled after `label`.
pub fn run_budget(
    scene: &Scene,
    options: &SequenceOptions,
    how: Measuring,
    whole: &SequenceRun,
    label: &str,
) -> Result<Budget> {
    let present = Effect::ALL.map(|e| e.present(scene, options));
    // The steps from the last effect present on are the sequence as asked.
    let last = present.iter().rposition(|&p| p).map_or(0, |i| i + 1);
    let mut steps: Vec<BudgetStep> = Vec::new();
    for k in 0..=Effect::ALL.len() {
        let added = k.checked_sub(1).map(|i| Effect::ALL[i]);
        let has = added.is_none() || present[k - 1];
        let step = if k >= last {
            BudgetStep::of(added, has, whole)
        } else if !has {
            let before = &steps[k - 1];
            BudgetStep {
                added,
                present: false,
                ..before.clone()
            }
        } else {
            let (mut s, mut o) = (scene.clone(), options.clone());
            for e in &Effect::ALL[k..] {
                e.remove(&mut s, &mut o);
            }
            let name = format!("{label}, budget: {}", added.map_or("none", Effect::label));
            let run = run_sequence_labelled(&s, o, how, &name, &mut |_| Ok(()))?;
            BudgetStep::of(added, has, &run)
        };
        steps.push(step);
    }
    Ok(Budget { steps })
}

impl Budget {
    /// Each step's change from the one before, arc-minutes (the baseline's: its mean).
    pub fn changes(&self) -> Vec<f64> {
        let mut before = 0.0;
        self.steps
            .iter()
            .map(|s| {
                let change = s.mean_arcmin - before;
                before = s.mean_arcmin;
                change
            })
            .collect()
    }

    /// budget.csv: one row per step.
    pub fn csv(&self) -> String {
        let mut text = String::from(
            "step,effect,present,mean_of_frame_means_arcmin,change_arcmin,mean_of_frame_p95_arcmin,coverage_mean\n",
        );
        for (k, (s, change)) in self.steps.iter().zip(self.changes()).enumerate() {
            let effect = s.added.map_or("none", Effect::label);
            text += &format!(
                "{k},{effect},{},{:.6},{change:.6},{:.6},{:.6}\n",
                s.present, s.mean_arcmin, s.p95_arcmin, s.coverage
            );
        }
        text
    }

    /// summary.json's `budget`.
    pub fn json(&self) -> serde_json::Value {
        let steps: Vec<serde_json::Value> = self
            .steps
            .iter()
            .zip(self.changes())
            .map(|(s, change)| {
                serde_json::json!({
                    "added": s.added,
                    "present": s.present,
                    "mean_of_frame_means_arcmin": s.mean_arcmin,
                    "change_arcmin": change,
                    "mean_of_frame_p95_arcmin": s.p95_arcmin,
                    "coverage_mean": s.coverage,
                })
            })
            .collect();
        serde_json::json!({
            "steps": steps,
            "definition": "the sequence run again with the effects of time added one by one to a baseline without any (no latency, a display refresh at every frame, instant shutters for both cameras, a display that shows each refresh at once), in the order of steps; change_arcmin: what the step's effect adds to the mean of frame means after those before it (the changes sum to the sequence's mean; misregistrations are lengths, so a change depends on the effects before it); present false: the sequence has no such effect and the step is the one before; means over the display pixels that show the scene (coverage_mean beside them)",
        })
    }

    /// One line: each step's mean and change.
    pub fn headline(&self) -> String {
        let parts: Vec<String> = self
            .steps
            .iter()
            .zip(self.changes())
            .map(|(s, change)| match s.added {
                None => format!("{:.1}′ without effects of time", s.mean_arcmin),
                Some(e) if !s.present => format!("{} none", e.label()),
                Some(e) => format!("{} {change:+.1}′", e.label()),
            })
            .collect();
        format!("budget: {}", parts.join(", "))
    }

    /// budget_over_time.png: misregistration over time with the effects added one by one, so that the
    /// gap between two curves is what an effect adds (steps without their effect are left
    /// out: the curve before is theirs).
    pub fn figure(&self, duration: f64) -> Figure {
        let mut figure = over_time_figure(
            &self
                .steps
                .iter()
                .filter(|s| s.present)
                .map(|s| {
                    let name = s
                        .added
                        .map_or("none".to_string(), |e| format!("+ {}", e.label()));
                    (name, s.records.as_slice())
                })
                .collect::<Vec<_>>(),
            duration,
        );
        figure.title = "Misregistration budget: the effects of time added one by one".into();
        figure
    }
}
