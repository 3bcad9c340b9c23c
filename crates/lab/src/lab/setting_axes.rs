//! Axes over any dial of a frame: a path into [`FrameSettings`] (`post.bloom`,
//! `lights.shape`, `view.msaa`) and the values it takes, multiplied in the order they are
//! listed (the first outermost). A dial added to the settings is an axis with no edit
//! here: the values are applied by the settings' one setter
//! ([`FrameSettings::set`]), checked when the matrix is read, stored in each
//! configuration and its report as written, and read back as data.
//!
//! In a matrix's TOML:
//!
//! ```toml
//! [settings]
//! "post.anti_aliasing" = ["off", "taa"]
//! "post.bloom" = [0, 0.04]
//! ```

use indexmap::IndexMap;
use manylights::FrameSettings;
use serde::{Deserialize, Serialize};
use serde_json::Value;

/// One configuration's values of the setting axes, by path, in the axes' order.
pub type SettingValues = IndexMap<String, Value>;

/// The setting axes of a matrix: each path with the values it takes.
#[derive(Debug, Clone, Default, PartialEq, Serialize, Deserialize)]
#[serde(transparent)]
pub struct SettingAxes(pub IndexMap<String, Vec<Value>>);

impl SettingAxes {
    pub fn is_empty(&self) -> bool {
        self.0.is_empty()
    }

    /// The values an axis takes; empty where the matrix does not vary it.
    pub fn values(&self, path: &str) -> &[Value] {
        self.0.get(path).map_or(&[], Vec::as_slice)
    }

    /// Sets an axis, in its place if the matrix has it, else after the others (the
    /// command line's axes replace a matrix's).
    pub fn replace(&mut self, path: &str, values: Vec<Value>) {
        self.0.insert(path.to_string(), values);
    }

    /// Every path exists and every value is one its field takes (on the default
    /// settings), or the error naming the path and the value.
    pub fn validate(&self) -> Result<(), String> {
        for (path, values) in &self.0 {
            if values.is_empty() {
                return Err(format!(
                    "setting axis `{path}` has no values: give one or more"
                ));
            }
            for value in values {
                FrameSettings::default()
                    .set(path, value.clone())
                    .map_err(|error| error.to_string())?;
            }
        }
        Ok(())
    }

    /// Every combination of the axes' values, in run order: one loop over the axes, each
    /// multiplying the combinations before it.
    pub fn choices(&self) -> Vec<SettingValues> {
        let mut choices = vec![SettingValues::new()];
        for (path, values) in &self.0 {
            choices = choices
                .into_iter()
                .flat_map(|choice| {
                    values.iter().map(move |value| {
                        let mut next = choice.clone();
                        next.insert(path.clone(), value.clone());
                        next
                    })
                })
                .collect();
        }
        choices
    }
}

/// Applies a configuration's setting values to its frame.
pub fn apply(settings: &mut FrameSettings, values: &SettingValues) -> Result<(), String> {
    for (path, value) in values {
        settings
            .set(path, value.clone())
            .map_err(|error| error.to_string())?;
    }
    Ok(())
}

/// The values that differ from the default settings', as a label's part:
/// ` + post.anti_aliasing=taa + post.bloom=0.04` (a text value unquoted).
pub fn label(values: &SettingValues) -> String {
    let defaults = FrameSettings::default();
    let mut label = String::new();
    for (path, value) in values {
        if !is_default(&defaults, path, value) {
            let shown = match value {
                Value::String(text) => text.clone(),
                other => other.to_string(),
            };
            label.push_str(&format!(" + {path}={shown}"));
        }
    }
    label
}

/// Whether `value` at `path` is what the default settings hold (compared as the field
/// reads it back: `0` and `0.0` are the same bloom).
fn is_default(defaults: &FrameSettings, path: &str, value: &Value) -> bool {
    let mut set = defaults.clone();
    set.set(path, value.clone()).is_ok() && set == *defaults
}

/// The dials the matrix and its configurations named by their own fields before they
/// were setting axes: (the matrix's axis, a configuration's field, the path). Reading a
/// matrix or a report moves them into the setting axes, so files written before read
/// back as they ran, and the run order is theirs (the first outermost).
pub const NAMED_BEFORE: [(&str, &str, &str); 5] = [
    ("light_shapes", "light_shape", "lights.shape"),
    ("msaa", "msaa", "view.msaa"),
    ("transparencies", "transparency", "transparency"),
    ("anti_aliasing", "anti_aliasing", "post.anti_aliasing"),
    ("blooms", "bloom", "post.bloom"),
];

/// A matrix as written (TOML read as data, or a report's): its named axes of
/// [`NAMED_BEFORE`] moved into `settings`, before the axes it lists there (an axis of one
/// default value is dropped: it is every configuration's).
pub fn upgrade_matrix(matrix: &mut Value) {
    let Some(fields) = matrix.as_object_mut() else {
        return;
    };
    let defaults = FrameSettings::default();
    let mut axes = serde_json::Map::new();
    for (axis, _, path) in NAMED_BEFORE {
        if let Some(Value::Array(values)) = fields.remove(axis) {
            let only_default = matches!(&values[..], [value] if is_default(&defaults, path, value));
            if !only_default {
                axes.insert(path.to_string(), Value::Array(values));
            }
        }
    }
    if let Some(Value::Object(listed)) = fields.remove("settings") {
        axes.extend(listed);
    }
    if !axes.is_empty() {
        fields.insert("settings".into(), Value::Object(axes));
    }
}

/// A configuration as a report wrote it: its fields of [`NAMED_BEFORE`] moved into its
/// `settings` where its matrix varied them (`axes`, the upgraded matrix's paths) or they
/// differ from the default, as the matrix run again gives them.
pub fn upgrade_config(config: &mut Value, axes: &[String]) {
    let Some(fields) = config.as_object_mut() else {
        return;
    };
    let defaults = FrameSettings::default();
    let mut values = serde_json::Map::new();
    for (_, field, path) in NAMED_BEFORE {
        if let Some(value) = fields.remove(field)
            && (axes.iter().any(|axis| axis == path) || !is_default(&defaults, path, &value))
        {
            values.insert(path.to_string(), value);
        }
    }
    if let Some(Value::Object(listed)) = fields.remove("settings") {
        values.extend(listed);
    }
    if !values.is_empty() {
        fields.insert("settings".into(), Value::Object(values));
    }
}

/// A report (`bench.json`) as written: its matrix and every configuration upgraded.
pub fn upgrade_report(report: &mut Value) {
    let mut axes = Vec::new();
    if let Some(matrix) = report.get_mut("matrix") {
        upgrade_matrix(matrix);
        if let Some(Value::Object(listed)) = matrix.get("settings") {
            axes = listed.keys().cloned().collect();
        }
    }
    if let Some(Value::Array(results)) = report.get_mut("results") {
        for result in results {
            if let Some(config) = result.get_mut("config") {
                upgrade_config(config, &axes);
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use serde_json::json;

    #[test]
    fn the_product_of_axes_is_in_their_order_the_first_outermost() {
        let mut axes = SettingAxes::default();
        axes.replace("post.anti_aliasing", vec![json!("off"), json!("taa")]);
        axes.replace("post.bloom", vec![json!(0), json!(0.04)]);
        let choices: Vec<String> = axes.choices().iter().map(label).collect();
        assert_eq!(
            choices,
            [
                "",
                " + post.bloom=0.04",
                " + post.anti_aliasing=taa",
                " + post.anti_aliasing=taa + post.bloom=0.04"
            ]
        );
        assert!(axes.validate().is_ok());
    }

    #[test]
    fn a_wrong_axis_is_refused_naming_its_path() {
        let mut axes = SettingAxes::default();
        axes.replace("post.blom", vec![json!(0.1)]);
        assert!(axes.validate().unwrap_err().contains("post.blom"));
        let mut axes = SettingAxes::default();
        axes.replace("post.anti_aliasing", vec![json!("fxaa")]);
        assert!(axes.validate().unwrap_err().contains("fxaa"));
        let mut axes = SettingAxes::default();
        axes.replace("view.msaa", Vec::new());
        assert!(axes.validate().unwrap_err().contains("view.msaa"));
    }

    #[test]
    fn named_axes_written_before_become_setting_axes_in_their_run_order() {
        let mut matrix = json!({
            "blooms": [0.0, 0.04],
            "msaa": [1],
            "anti_aliasing": ["off", "taa"],
            "settings": {"shadows.mode": ["off", "exact"]}
        });
        upgrade_matrix(&mut matrix);
        assert_eq!(
            matrix,
            json!({"settings": {
                "post.anti_aliasing": ["off", "taa"],
                "post.bloom": [0.0, 0.04],
                "shadows.mode": ["off", "exact"]
            }})
        );
        let keys: Vec<&String> = matrix["settings"].as_object().unwrap().keys().collect();
        assert_eq!(keys, ["post.anti_aliasing", "post.bloom", "shadows.mode"]);
        let mut config = json!({"msaa": 4, "bloom": 0.0, "light_shape": "rect:0.4"});
        upgrade_config(&mut config, &[]);
        assert_eq!(
            config,
            json!({"settings": {"lights.shape": "rect:0.4", "view.msaa": 4}})
        );
        // A value the matrix varied is kept, the default among them.
        let mut config = json!({"msaa": 1, "bloom": 0.0});
        upgrade_config(&mut config, &["view.msaa".to_string()]);
        assert_eq!(config, json!({"settings": {"view.msaa": 1}}));
    }
}
