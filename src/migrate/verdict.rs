//! The plan's perceptual verdict on a material: how far its appearance as written lies from
//! its appearance as authored, as a viewer would judge it (NVIDIA's ꟻLIP over small renders of
//! the material before and after, in a white furnace and under one light), and the words
//! same / close / visible that the thresholds give it.
//!
//! This module owns the values and the thresholds; the measurement is made by the preview's
//! renderer (`preview::verdict`), which draws from migrate's plan and so lies above it, and the
//! result is written into the plan ([`super::MaterialPlan::verdict`]) right after planning.
//! Every view reads it from there: migrate's reports, `--check --fail-on-visible`, and the
//! preview's labels and ranking.

use serde::Serialize;

/// At most this ꟻLIP (99th percentile over the sphere in the furnace, the largest over a
/// material's swatches): "same to the eye". Calibrated in docs/preview.md.
pub const SAME_FLIP: f64 = 0.10;
/// At most this ꟻLIP: "close"; above it, "visible".
pub const CLOSE_FLIP: f64 = 0.22;

/// What the picture says, in a word.
#[derive(Clone, Copy, Debug, PartialEq, Eq, PartialOrd, Ord, Hash, Serialize)]
#[serde(rename_all = "lowercase")]
pub enum Label {
    Same,
    Close,
    Visible,
}

impl Label {
    /// The label of a furnace ꟻLIP value (see [`SAME_FLIP`], [`CLOSE_FLIP`]).
    pub fn from_flip(flip: f64) -> Label {
        if flip <= SAME_FLIP {
            Label::Same
        } else if flip <= CLOSE_FLIP {
            Label::Close
        } else {
            Label::Visible
        }
    }

    /// The label as JSON writes it.
    pub fn as_str(self) -> &'static str {
        match self {
            Label::Same => "same",
            Label::Close => "close",
            Label::Visible => "visible",
        }
    }

    /// The label in a sentence.
    pub fn text(self) -> &'static str {
        match self {
            Label::Same => "same to the eye",
            Label::Close => "close",
            Label::Visible => "visible difference: look before trusting it",
        }
    }
}

/// A material's verdict: the label, the ꟻLIP that decides it (the furnace's), and the ꟻLIP
/// under the directional light beside it. The lobes of sheen and fuzz differ in shape for every
/// pair (the fitted mapping matches their energy), so the light's value is reported but does
/// not decide the label; see docs/preview.md.
#[derive(Clone, Copy, Debug, PartialEq, Serialize)]
pub struct Verdict {
    pub label: Label,
    /// The furnace's ꟻLIP: the label's measure.
    pub flip: f64,
    /// The furnace's ꟻLIP (equal to `flip`), named beside the light's.
    pub furnace: f64,
    /// The ꟻLIP under the directional light.
    pub light: f64,
}

impl Verdict {
    /// The verdict of a furnace and a light ꟻLIP, each rounded to four decimals (ꟻLIP computes
    /// in f32, whose further digits are noise), the label read from the rounded value so that
    /// the label and the number a report prints always agree.
    pub fn new(furnace: f64, light: f64) -> Verdict {
        let round = |v: f64| (v * 1e4).round() / 1e4;
        let (furnace, light) = (round(furnace), round(light));
        // The furnace decides; but "same to the eye" must hold under the light too: a material
        // the light shows more than close apart is close at best.
        let label = match Label::from_flip(furnace) {
            Label::Same if light > CLOSE_FLIP => Label::Close,
            label => label,
        };
        Verdict {
            label,
            flip: furnace,
            furnace,
            light,
        }
    }

    /// "close (ꟻLIP 0.135 in the furnace, 0.384 under the light)".
    pub fn describe(&self) -> String {
        format!(
            "{} (ꟻLIP {:.3} in the furnace, {:.3} under the light)",
            self.label.as_str(),
            self.furnace,
            self.light
        )
    }
}

/// What would bring a "visible" material closer: the flags of a run that would migrate it so,
/// and the verdict it would reach.
#[derive(Clone, Debug, PartialEq, Serialize)]
pub struct Remedy {
    /// The flags, as typed: "--exact", "--roughness-budget exact", or both.
    pub flags: String,
    pub verdict: Verdict,
}

/// The size budget within which the default takes, for a material whose migration is
/// "visible", the plan with more bakes that brings it to "close" or "same" (`--exact`, an exact
/// roughness bake): the uncompressed size (width × height × 4 bytes, which a PNG does not
/// exceed by much and mostly stays well under) of the new textures such plans add, per file,
/// taken in material order. 0 takes none. The default, 16 MiB, is 64 textures of 256².
#[derive(Clone, Copy, Debug, PartialEq, Eq)]
pub struct CloserBudget(pub u64);

/// The default [`CloserBudget`], in MiB.
pub const DEFAULT_CLOSER_BUDGET_MIB: u64 = 16;

impl Default for CloserBudget {
    fn default() -> Self {
        CloserBudget(DEFAULT_CLOSER_BUDGET_MIB << 20)
    }
}

/// A remedy left untaken: the new textures it needs would pass the budget.
#[derive(Clone, Copy, Debug, PartialEq, Eq, Serialize)]
pub struct BeyondBudget {
    /// The new textures' uncompressed size, in bytes.
    pub bytes: u64,
    /// What was left of the file's budget, in bytes.
    pub left: u64,
}

/// Counts of materials by label, for a run's summary.
#[derive(Clone, Copy, Debug, Default, PartialEq, Eq, Serialize)]
pub struct LabelCounts {
    pub same: usize,
    pub close: usize,
    pub visible: usize,
}

impl LabelCounts {
    pub fn add(&mut self, label: Label) {
        match label {
            Label::Same => self.same += 1,
            Label::Close => self.close += 1,
            Label::Visible => self.visible += 1,
        }
    }

    pub fn total(&self) -> usize {
        self.same + self.close + self.visible
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn labels_follow_the_thresholds_inclusively() {
        assert_eq!(Label::from_flip(0.0), Label::Same);
        assert_eq!(Label::from_flip(SAME_FLIP), Label::Same);
        assert_eq!(Label::from_flip(0.1000001), Label::Close);
        assert_eq!(Label::from_flip(CLOSE_FLIP), Label::Close);
        assert_eq!(Label::from_flip(0.2200001), Label::Visible);
        let v = Verdict::new(0.307, 0.294);
        assert_eq!(v.label, Label::Visible);
        assert_eq!(
            serde_json::to_value(v).unwrap(),
            serde_json::json!({"label": "visible", "flip": 0.307, "furnace": 0.307, "light": 0.294})
        );
        assert_eq!(
            v.describe(),
            "visible (ꟻLIP 0.307 in the furnace, 0.294 under the light)"
        );
        // Same in the furnace but more than close under the light: close; the light never
        // makes a verdict worse than close, and the ranking measure stays the furnace's.
        assert_eq!(Verdict::new(0.08, 0.22).label, Label::Same);
        let lit = Verdict::new(0.08, 0.284);
        assert_eq!((lit.label, lit.flip), (Label::Close, 0.08));
        assert_eq!(Verdict::new(0.15, 0.9).label, Label::Close);
    }
}
