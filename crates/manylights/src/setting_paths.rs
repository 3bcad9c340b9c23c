//! Settings as data: every dial of a frame is a path into [`FrameSettings`] (its fields'
//! names joined by dots: `post.bloom`, `lights.shape`, `pipeline.clustering.grid.z_slices`)
//! and is read and written through the settings' serialized form, so one setter reaches
//! every field, a field added tomorrow included. The lab's axes, the command line's
//! `--set`, the page's URL parameters and the reports all go through it.
//!
//! A value is written as the field serializes: the command line's spelling for a named
//! choice (`taa`, `rect:0.4`, `tree:0.1`), a number, `true`/`false`, or JSON for a
//! structured value (`post.exposure = {"manual": 2}`).

use serde_json::Value;

use crate::FrameSettings;

/// Why a setting could not be read or written: the path and what is wrong with it.
#[derive(Debug, Clone, PartialEq, thiserror::Error)]
pub enum SettingError {
    /// No field at this path; `known` lists the fields where the path left the settings.
    #[error("no setting `{path}`: {}", known_fields(.parent, .known))]
    UnknownPath {
        path: String,
        parent: String,
        known: Vec<String>,
    },
    /// The field exists but refuses the value.
    #[error("setting `{path}` to {value}: {reason}")]
    InvalidValue {
        path: String,
        value: String,
        reason: String,
    },
}

fn known_fields(parent: &str, known: &[String]) -> String {
    let place = if parent.is_empty() {
        "the settings have".to_string()
    } else {
        format!("`{parent}` has")
    };
    if known.is_empty() {
        format!("{place} no fields below it")
    } else {
        format!("{place} {}", known.join(", "))
    }
}

impl FrameSettings {
    /// These settings as data (the form every path reads).
    pub fn to_value(&self) -> Value {
        serde_json::to_value(self).expect("frame settings always serialize")
    }

    /// The settings a serialized form describes (a report's, a file's).
    pub fn from_value(value: Value) -> Result<Self, String> {
        serde_json::from_value(value).map_err(|error| error.to_string())
    }

    /// The value at `path`, as the field serializes.
    pub fn get(&self, path: &str) -> Result<Value, SettingError> {
        let value = self.to_value();
        lookup(&value, path).cloned()
    }

    /// Sets the field at `path` to `value` (in the field's serialized form). The whole
    /// settings are rebuilt from their data, so a value the field's type refuses (a
    /// misspelt name, a negative count) is an error naming the path, and the settings keep
    /// what they had.
    ///
    /// An enum's data is a one-field section named by its variant (`post.exposure.manual`,
    /// `lights.radius.fixed`): setting another variant's field switches to that variant
    /// (`post.exposure.manual = 2` on automatic exposure makes it manual).
    pub fn set(&mut self, path: &str, value: Value) -> Result<(), SettingError> {
        let mut data = self.to_value();
        match lookup_mut(&mut data, path) {
            Ok(field) => *field = value.clone(),
            Err(error) => {
                let (parent, variant) = path.rsplit_once('.').ok_or(error.clone())?;
                let section = lookup_mut(&mut data, parent).map_err(|_| error.clone())?;
                if section.as_object().is_none_or(|fields| fields.len() != 1) {
                    return Err(error);
                }
                *section = serde_json::json!({ variant: value.clone() });
            }
        }
        *self = Self::from_value(data).map_err(|reason| SettingError::InvalidValue {
            path: path.to_string(),
            value: value.to_string(),
            reason,
        })?;
        Ok(())
    }

    /// [`Self::set`] from text, as a person writes it (`--set post.bloom=0.05`, a URL
    /// parameter): text for a field held as text (a named choice), `on`/`off` for a switch
    /// as well as `true`/`false`, else the text read as JSON (a number, `true`,
    /// `{"manual": 2}`), else the text itself.
    pub fn set_text(&mut self, path: &str, text: &str) -> Result<(), SettingError> {
        let value = self.value_from_text(path, text);
        self.set(path, value)
    }

    /// The value `text` writes at `path` (by [`Self::set_text`]'s rule), unchecked: the
    /// lab keeps an axis's values as they were written.
    pub fn value_from_text(&self, path: &str, text: &str) -> Value {
        // A path that is not there yet (another variant's field) is read as JSON too;
        // `set` says whether it exists.
        match (self.get(path), text) {
            (Ok(Value::String(_)), _) => Value::String(text.to_string()),
            // A switch reads as the command line has always written it, too.
            (Ok(Value::Bool(_)), "on") => Value::Bool(true),
            (Ok(Value::Bool(_)), "off") => Value::Bool(false),
            _ => serde_json::from_str(text).unwrap_or_else(|_| Value::String(text.to_string())),
        }
    }

    /// `PATH=VALUE`, as `--set` and the lab's overrides write it.
    pub fn set_assignment(&mut self, assignment: &str) -> Result<(), SettingError> {
        let (path, text) =
            assignment
                .split_once('=')
                .ok_or_else(|| SettingError::InvalidValue {
                    path: assignment.to_string(),
                    value: String::new(),
                    reason: "expected PATH=VALUE, e.g. post.bloom=0.05".into(),
                })?;
        self.set_text(path.trim(), text.trim())
    }

    /// Every leaf's path (a field that holds a value, not a section), in the settings'
    /// order: what a test walks to show every dial reachable.
    pub fn setting_paths(&self) -> Vec<String> {
        let mut paths = Vec::new();
        collect_leaves(&self.to_value(), String::new(), &mut paths);
        paths
    }
}

fn lookup<'a>(mut value: &'a Value, path: &str) -> Result<&'a Value, SettingError> {
    let mut walked = String::new();
    for key in path.split('.') {
        value = match value.get(key) {
            Some(inner) => inner,
            None => return Err(unknown(path, &walked, value)),
        };
        push_key(&mut walked, key);
    }
    Ok(value)
}

fn lookup_mut<'a>(mut value: &'a mut Value, path: &str) -> Result<&'a mut Value, SettingError> {
    let mut walked = String::new();
    for key in path.split('.') {
        if value.get(key).is_none() {
            return Err(unknown(path, &walked, value));
        }
        value = value.get_mut(key).expect("the key was just found");
        push_key(&mut walked, key);
    }
    Ok(value)
}

fn push_key(walked: &mut String, key: &str) {
    if !walked.is_empty() {
        walked.push('.');
    }
    walked.push_str(key);
}

fn unknown(path: &str, parent: &str, at: &Value) -> SettingError {
    SettingError::UnknownPath {
        path: path.to_string(),
        parent: parent.to_string(),
        known: at
            .as_object()
            .map(|fields| fields.keys().cloned().collect())
            .unwrap_or_default(),
    }
}

fn collect_leaves(value: &Value, prefix: String, paths: &mut Vec<String>) {
    match value.as_object() {
        // A section: its fields. (An enum's data, `{"manual": 1}`, is a section too: its
        // one field is the variant's, set whole at the parent's path to change variant.)
        Some(fields) if !fields.is_empty() => {
            for (key, inner) in fields {
                let mut path = prefix.clone();
                push_key(&mut path, key);
                collect_leaves(inner, path, paths);
            }
        }
        _ => paths.push(prefix),
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::{AntiAliasing, PipelineKind};
    use manylights_lights::LightShape;

    #[test]
    fn the_default_settings_round_trip_through_their_data() {
        let settings = FrameSettings::default();
        assert_eq!(FrameSettings::from_value(settings.to_value()), Ok(settings));
        let mut far = FrameSettings::default();
        far.view.camera.far = f32::INFINITY;
        assert_eq!(FrameSettings::from_value(far.to_value()), Ok(far));
    }

    #[test]
    fn a_path_sets_the_field_it_names_in_its_own_spelling() {
        let mut settings = FrameSettings::default();
        settings.set_text("post.anti_aliasing", "taa").unwrap();
        settings.set_text("post.bloom", "0.05").unwrap();
        settings.set_text("lights.shape", "rect:0.4").unwrap();
        settings.set_assignment("view.msaa = 4").unwrap();
        settings.set_text("view.size", "640x360").unwrap();
        assert_eq!(settings.post.anti_aliasing, AntiAliasing::Taa);
        assert_eq!(settings.post.bloom, 0.05);
        assert_eq!(settings.lights.shape, LightShape::Rect(0.4));
        assert_eq!(settings.view.msaa, 4);
        assert_eq!(settings.view.size, (640, 360));
        settings.set_text("budget", "8").unwrap();
        assert_eq!(settings.budget, Some(8.0));
        settings.set_text("lights.radius.fixed", "3").unwrap();
        assert_eq!(
            settings.lights.radius,
            manylights_lights::RadiusMode::Fixed(3.0)
        );
        assert!(settings.set_text("lights.radius.fxed", "3").is_err());
        // A switch takes the command line's `on`/`off` as well as JSON's spelling.
        settings.set_text("lights.emissive", "off").unwrap();
        assert!(!settings.lights.emissive);
        settings.set_text("lights.emissive", "true").unwrap();
        assert!(settings.lights.emissive);
        assert!(settings.set_text("lights.emissive", "maybe").is_err());
    }

    #[test]
    fn a_pipeline_is_switched_by_its_kind_and_keeps_its_own_fields_defaults() {
        let mut settings = FrameSettings::default();
        settings.set_text("pipeline.kind", "forward-plus").unwrap();
        assert_eq!(settings.pipeline.kind(), PipelineKind::ForwardPlus);
        settings
            .set_text("pipeline.clustering.grid.z_slices", "24")
            .unwrap();
        assert_eq!(settings.pipeline.clustering().unwrap().grid.z_slices, 24);
    }

    #[test]
    fn a_wrong_path_or_value_names_itself_and_changes_nothing() {
        let mut settings = FrameSettings::default();
        let before = settings.clone();
        let error = settings.set_text("post.blom", "0.1").unwrap_err();
        assert!(error.to_string().contains("post.blom"), "{error}");
        assert!(error.to_string().contains("bloom"), "{error}");
        let error = settings.set_text("post.anti_aliasing", "fxaa").unwrap_err();
        assert!(error.to_string().contains("post.anti_aliasing"), "{error}");
        assert!(error.to_string().contains("taa"), "{error}");
        assert!(settings.set_text("view.msaa", "-1").is_err());
        assert!(settings.set_assignment("view.msaa").is_err());
        assert_eq!(settings, before);
    }

    #[test]
    fn every_leaf_reads_back_what_it_was_set_to() {
        let settings = FrameSettings::default();
        let paths = settings.setting_paths();
        assert!(paths.contains(&"post.bloom".to_string()), "{paths:?}");
        assert!(
            paths.contains(&"view.camera.position".to_string()),
            "{paths:?}"
        );
        for path in paths {
            let mut copy = settings.clone();
            let value = settings.get(&path).unwrap();
            copy.set(&path, value.clone()).unwrap();
            assert_eq!(copy.get(&path).unwrap(), value, "{path}");
            assert_eq!(copy, settings, "{path}");
        }
    }
}
