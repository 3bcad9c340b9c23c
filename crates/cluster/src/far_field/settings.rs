//! What a frame asks of the far field: the method, its tolerance and (for the tree) the
//! slots a cluster's cut may hold; named and parsed as `tree:TOLERANCE[:SLOTS]` or
//! `stochastic[:TOLERANCE]`.

use super::{DEFAULT_FAR_CUT_SLOTS, MAX_FAR_CUT_SLOTS};

/// How lights beyond their radius are approximated.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
#[derive(serde_with::SerializeDisplay, serde_with::DeserializeFromStr)]
pub enum FarFieldMethod {
    /// A light tree and a cut per cluster: deterministic, biased, one parameter.
    Tree,
    /// Stochastic light culling: unbiased, noisy, reproducible per seed.
    Stochastic,
}

impl FarFieldMethod {
    pub const ALL: [FarFieldMethod; 2] = [FarFieldMethod::Tree, FarFieldMethod::Stochastic];

    pub fn name(&self) -> &'static str {
        match self {
            FarFieldMethod::Tree => "tree",
            FarFieldMethod::Stochastic => "stochastic",
        }
    }

    /// The tolerance used when none is given: where each method's measured speed/accuracy
    /// trade is best at the reference workload (docs/results/nvidia-h200/far-field).
    pub fn default_tolerance(&self) -> f32 {
        match self {
            FarFieldMethod::Tree => 1.0,
            FarFieldMethod::Stochastic => 1.0,
        }
    }

    /// Code in `FarFieldParams::setup.x` (`FAR_FIELD_*` in far_nodes.wgsl); no far field is
    /// [`FarFieldMethod::OFF_CODE`].
    pub(crate) fn shader_code(&self) -> u32 {
        match self {
            FarFieldMethod::Tree => 1,
            FarFieldMethod::Stochastic => 2,
        }
    }

    pub(crate) const OFF_CODE: u32 = 0;
}

manylights_gpu::named_choice!(FarFieldMethod, "far-field method");

/// A far field: the method, its tolerance and (stochastic) its seed.
///
/// `tolerance`: for the tree, the largest error bound a node may have relative to the
/// cluster's estimated far-field total (0: every light exactly); for stochastic culling, the
/// scale of the random ranges (range = r / sqrt(tolerance x xi); 0: every light reaches
/// everywhere, exactly; larger: shorter ranges, more noise).
///
/// `slots` (the tree): the most entries one cluster's cut may hold. The cut stops refining
/// when they are full, whatever the tolerance: at many lights they, not the tolerance,
/// bound the error (H200, 1,000,000 lights: 64 slots 0.028-0.033, 192 slots 0.013-0.015), and they
/// bound each pixel's far-field cost.
#[derive(Debug, Clone, Copy, PartialEq)]
#[derive(serde::Serialize)]
pub struct FarField {
    pub method: FarFieldMethod,
    pub tolerance: f32,
    pub seed: u32,
    pub slots: u32,
}

impl FarField {
    /// The method with its default tolerance and slots, and seed 0.
    pub fn new(method: FarFieldMethod) -> Self {
        Self {
            method,
            tolerance: method.default_tolerance(),
            seed: 0,
            slots: DEFAULT_FAR_CUT_SLOTS,
        }
    }

    /// The method with this tolerance (default slots, seed 0).
    pub fn with_tolerance(method: FarFieldMethod, tolerance: f32) -> Self {
        Self {
            tolerance,
            ..Self::new(method)
        }
    }

    /// A finite, non-negative tolerance and slots from 1 to [`MAX_FAR_CUT_SLOTS`] (the
    /// default for stochastic culling, which has no cut), or why not.
    pub fn validate(&self) -> Result<(), String> {
        if !self.tolerance.is_finite() || self.tolerance < 0.0 {
            return Err(format!(
                "far-field tolerance {} must be a finite number at least 0",
                self.tolerance
            ));
        }
        if !(1..=MAX_FAR_CUT_SLOTS).contains(&self.slots) {
            return Err(format!(
                "far-field slots {} must be from 1 to {MAX_FAR_CUT_SLOTS}",
                self.slots
            ));
        }
        if self.method == FarFieldMethod::Stochastic && self.slots != DEFAULT_FAR_CUT_SLOTS {
            return Err(
                "stochastic culling has no cut: slots are the tree's (tree:TOLERANCE:SLOTS)".into(),
            );
        }
        Ok(())
    }
}

/// `METHOD:TOLERANCE`, with `:SLOTS` when not the default.
impl std::fmt::Display for FarField {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        write!(f, "{}:{}", self.method, self.tolerance)?;
        if self.slots != DEFAULT_FAR_CUT_SLOTS {
            write!(f, ":{}", self.slots)?;
        }
        Ok(())
    }
}

/// `METHOD`, `METHOD:TOLERANCE` or `tree:TOLERANCE:SLOTS`, e.g. `tree`, `tree:0.05`,
/// `tree:1:192`, `stochastic:1`.
impl std::str::FromStr for FarField {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        let mut parts = text.split(':');
        let mut far = FarField::new(parts.next().unwrap_or_default().parse()?);
        if let Some(tolerance) = parts.next() {
            far.tolerance = tolerance
                .parse()
                .map_err(|_| format!("far-field tolerance `{tolerance}` is not a number"))?;
        }
        if let Some(slots) = parts.next() {
            far.slots = slots
                .parse()
                .map_err(|_| format!("far-field slots `{slots}` is not a whole number"))?;
        }
        if parts.next().is_some() {
            return Err(format!(
                "far field `{text}`: expected METHOD, METHOD:TOLERANCE or tree:TOLERANCE:SLOTS"
            ));
        }
        far.validate()?;
        Ok(far)
    }
}

/// Read from its fields (as it is written) or from its name (`tree:0.1`, as a person
/// writes it: `--set pipeline.clustering.far_field=tree:0.1`); either is validated.
impl<'de> serde::Deserialize<'de> for FarField {
    fn deserialize<D: serde::Deserializer<'de>>(deserializer: D) -> Result<Self, D::Error> {
        #[derive(serde::Deserialize)]
        #[serde(untagged)]
        enum Written {
            Name(String),
            Fields {
                method: FarFieldMethod,
                tolerance: f32,
                seed: u32,
                slots: u32,
            },
        }
        let far = match Written::deserialize(deserializer)? {
            Written::Name(name) => name.parse().map_err(serde::de::Error::custom)?,
            Written::Fields {
                method,
                tolerance,
                seed,
                slots,
            } => FarField {
                method,
                tolerance,
                seed,
                slots,
            },
        };
        far.validate().map_err(serde::de::Error::custom)?;
        Ok(far)
    }
}

/// A far field or none, by name: `off`, or a [`FarField`]'s name (`tree`, `stochastic:1`,
/// ...). The spelling the CLI's `--far-field`, the lab's matrix and the page share.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct OptionalFarField(pub Option<FarField>);

impl std::str::FromStr for OptionalFarField {
    type Err = String;

    fn from_str(text: &str) -> Result<Self, String> {
        if text == "off" {
            return Ok(OptionalFarField(None));
        }
        Ok(OptionalFarField(Some(text.parse()?)))
    }
}

impl std::fmt::Display for OptionalFarField {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match &self.0 {
            None => f.write_str("off"),
            Some(far) => far.fmt(f),
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn names_and_tolerances_parse() {
        let far: FarField = "tree:0.25".parse().unwrap();
        assert_eq!(far.method, FarFieldMethod::Tree);
        assert_eq!(far.tolerance, 0.25);
        let far: FarField = "stochastic".parse().unwrap();
        assert_eq!(
            far.tolerance,
            FarFieldMethod::Stochastic.default_tolerance()
        );
        assert!("tree:-1".parse::<FarField>().is_err());
        assert!("tree:nan".parse::<FarField>().is_err());
        assert!("cone".parse::<FarField>().is_err());
    }

    #[test]
    fn the_trees_slots_parse_and_print_only_when_chosen() {
        let far: FarField = "tree:1".parse().unwrap();
        assert_eq!(far.slots, DEFAULT_FAR_CUT_SLOTS);
        assert_eq!(far.to_string(), "tree:1");
        let far: FarField = "tree:1:192".parse().unwrap();
        assert_eq!((far.tolerance, far.slots), (1.0, 192));
        assert_eq!(far.to_string(), "tree:1:192");
        assert_eq!(far.to_string().parse::<FarField>().unwrap(), far);
        let max = format!("tree:1:{MAX_FAR_CUT_SLOTS}");
        assert_eq!(max.parse::<FarField>().unwrap().slots, MAX_FAR_CUT_SLOTS);
        for bad in [
            "tree:1:0",
            "tree:1:-3",
            "tree:1:1.5",
            "tree:1:64:2",
            "stochastic:1:128",
        ] {
            let error = bad.parse::<FarField>().unwrap_err();
            assert!(!error.is_empty(), "{bad}");
        }
        let error = format!("tree:1:{}", MAX_FAR_CUT_SLOTS + 1)
            .parse::<FarField>()
            .unwrap_err();
        assert!(error.contains(&MAX_FAR_CUT_SLOTS.to_string()), "{error}");
    }
}
