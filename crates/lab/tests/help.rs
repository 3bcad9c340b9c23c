//! `manylights render --help` against what each option accepts.

use clap::CommandFactory;
use manylights::gpu::NamedChoice;
use manylights::{GBufferLayout, LightingPath, PipelineKind};
use manylights_lab::cli::RenderArgs;

fn names<T: NamedChoice>() -> Vec<String> {
    T::all()
        .iter()
        .map(|c| c.choice_name().to_string())
        .collect()
}

#[derive(clap::Parser)]
struct Render {
    #[command(flatten)]
    args: RenderArgs,
}

/// Every value any option of `render` accepts appears in `render --help`: each option
/// with a fixed set of names lists all of them, and the options whose values have
/// a syntax of their own (the far field, the debug views) name every method and view.
#[test]
fn every_accepted_value_appears_in_the_help() {
    let mut command = Render::command();
    let help = command.render_long_help().to_string();
    let mut listed = 0;
    for arg in command.get_arguments() {
        for value in arg.get_possible_values() {
            listed += 1;
            assert!(
                help.contains(value.get_name()),
                "--{} accepts `{}`, which its help does not show",
                arg.get_id(),
                value.get_name()
            );
        }
    }
    let possible = |id: &str| -> Vec<String> {
        let arg = command
            .get_arguments()
            .find(|a| a.get_id() == id)
            .unwrap_or_else(|| panic!("no option --{id}"));
        arg.get_possible_values()
            .iter()
            .map(|v| v.get_name().to_string())
            .collect()
    };
    assert_eq!(possible("gbuffer"), names::<GBufferLayout>());
    assert!(possible("gbuffer").contains(&"visibility".to_string()));
    assert_eq!(possible("lighting"), names::<LightingPath>());
    assert_eq!(possible("shadows"), names::<manylights::Shadows>());
    assert_eq!(possible("pipeline"), names::<PipelineKind>());
    assert!(
        listed >= 25,
        "only {listed} listed values: choices not wired to clap"
    );
    // Options with a syntax of their own name every method and view in their text.
    let text_of = |id: &str| -> String {
        command
            .get_arguments()
            .find(|a| a.get_id() == id)
            .and_then(|a| a.get_long_help().or(a.get_help()))
            .map(|h| h.to_string())
            .unwrap_or_default()
    };
    let far_field = text_of("far_field");
    for method in manylights::cluster::FarFieldMethod::ALL {
        assert!(
            far_field.contains(&format!("`{method}`")),
            "--far-field: {method}"
        );
    }
    assert!(far_field.contains("`off`"));
    let debug_view = text_of("debug_view");
    for view in manylights::cluster::ClusterView::ALL {
        assert!(
            debug_view.contains(&format!("`{view}`")),
            "--debug-view: {view}"
        );
    }
    for channel in manylights::deferred::GBufferChannel::ALL {
        assert!(
            debug_view.contains(&format!("`{channel}`")),
            "--debug-view: {channel}"
        );
    }
}
