//! A new dial costs one field: every field of [`FrameSettings`] (walked from its data, so a
//! field added to any section is in the walk with no edit here) is reachable from a lab
//! axis, a command-line flag, a page URL parameter and a report, each at a value other
//! than its default where the field's type gives one (a number moved, a flag flipped, a
//! choice's next name).

use clap::Parser;
use manylights::FrameSettings;
use serde_json::{Value, json};

use crate::cli::{Flags, url_query_args};
use crate::lab::{BenchConfig, BenchMatrix, frame_choice, setting_axes};

/// A value of the field at `path` other than `current` that the field takes, if one can
/// be derived from the field's data alone.
fn another_value(defaults: &FrameSettings, path: &str, current: &Value) -> Option<Value> {
    let candidates = match current {
        Value::Bool(flag) => vec![Value::Bool(!flag)],
        Value::Number(number) if number.is_u64() => vec![json!(number.as_u64()? + 1)],
        Value::Number(number) => vec![json!(number.as_f64()? * 0.5 + 0.25)],
        Value::Array(items) => vec![Value::Array(
            items
                .iter()
                .map(|item| json!(item.as_f64().unwrap_or(0.0) + 1.0))
                .collect(),
        )],
        // A choice refuses a wrong name listing the right ones: the first of them that is
        // not the current one.
        Value::String(_) | Value::Null => {
            let refusal = defaults
                .clone()
                .set(path, json!("not-a-name"))
                .err()?
                .to_string();
            let names = refusal.split("expected one of ").nth(1).unwrap_or("");
            let mut candidates: Vec<Value> = names
                .split([',', ' ', ')', '`'])
                .filter(|name| !name.is_empty())
                .map(|name| json!(name))
                .collect();
            // Then the spellings of the values written as text that are not a list of
            // names (a number, a far field, a shape, a size, a pair).
            candidates.extend(
                [
                    json!(1.0),
                    json!("tree:0.5"),
                    json!("rect:0.5"),
                    json!("640x360"),
                ]
                .into_iter()
                .chain([json!([1.0, 2.0])]),
            );
            candidates
        }
        Value::Object(_) => Vec::new(),
    };
    candidates.into_iter().find(|candidate| {
        candidate != current && {
            let mut set = defaults.clone();
            set.set(path, candidate.clone()).is_ok() && set != *defaults
        }
    })
}

/// `value` as a person types it on the command line or in a URL.
fn as_text(value: &Value) -> String {
    match value {
        Value::String(text) => text.clone(),
        other => other.to_string(),
    }
}

#[test]
fn every_setting_is_reachable_from_an_axis_a_flag_a_url_and_a_report() {
    let defaults = FrameSettings::default();
    let mut moved = Vec::new();
    let mut kept = Vec::new();
    for path in defaults.setting_paths() {
        let current = defaults.get(&path).unwrap();
        let value = another_value(&defaults, &path, &current).unwrap_or_else(|| {
            kept.push(path.clone());
            current.clone()
        });
        let mut expected = defaults.clone();
        expected.set(&path, value.clone()).unwrap();
        let wanted = expected.get(&path).unwrap();

        // A lab axis: the configuration holds the value and its frame has it.
        let mut matrix = BenchMatrix {
            pipelines: vec![defaults.pipeline.kind()],
            ..BenchMatrix::default()
        };
        matrix.settings.replace(&path, vec![value.clone()]);
        matrix.settings.validate().expect(&path);
        let config = BenchConfig {
            settings: matrix.settings.choices().remove(0),
            ..matrix_config(&matrix)
        };
        let (frame, _) = frame_choice(&matrix, &config).expect(&path);
        assert_eq!(frame.get(&path).unwrap(), wanted, "axis {path}");

        // A report: the configuration written and read back as data.
        let mut written = serde_json::to_value(&config).unwrap();
        setting_axes::upgrade_config(&mut written, std::slice::from_ref(&path));
        let read: BenchConfig = serde_json::from_value(written).expect(&path);
        assert_eq!(read, config, "report {path}");

        // A flag, and the page's URL parameter of the same path.
        let assignment = format!("{path}={}", as_text(&value));
        let flag = Flags::try_parse_from(["manylights", "--set", &assignment]).expect(&path);
        let from_flag = flag.args.settings().expect(&path);
        assert_eq!(from_flag.get(&path).unwrap(), wanted, "--set {assignment}");
        // A top-level path (`shading`, `budget`) may be a flag of its own with other
        // rules (the scene's BRDF): `?set=PATH=VALUE` reaches it as a setting.
        let pair = if path.contains('.') {
            (path.clone(), as_text(&value))
        } else {
            ("set".to_string(), assignment.clone())
        };
        let url = url_query_args([pair]);
        let page =
            Flags::try_parse_from(std::iter::once("manylights".into()).chain(url)).expect(&path);
        assert_eq!(
            page.args.settings().expect(&path).get(&path).unwrap(),
            wanted,
            "?{assignment}"
        );
        if wanted != current {
            moved.push(path);
        }
    }
    // The walk moved the fields a frame is made of, the named choices among them.
    for path in [
        "post.anti_aliasing",
        "post.bloom",
        "lights.shape",
        "view.msaa",
        "transparency",
        "shadows.mode",
        "pipeline.clustering.grid.z_slices",
        "lights.count",
    ] {
        assert!(
            moved.iter().any(|p| p == path),
            "{path} not moved: {moved:?}"
        );
    }
    assert!(moved.len() > 40, "moved {}, kept {kept:?}", moved.len());
    assert!(kept.len() <= 3, "kept at their defaults: {kept:?}");
}

/// The matrix's one configuration before its setting axes (the default settings'
/// pipeline, with the lab's defaults).
fn matrix_config(matrix: &BenchMatrix) -> BenchConfig {
    let mut plain = matrix.clone();
    plain.settings = Default::default();
    plain
        .configurations()
        .expect("the plain matrix has a configuration")
        .remove(0)
}
