//! The panel's "Every setting": the frame settings read as data, so a field added to
//! them is listed here with no edit.

use manylights::FrameSettings;

use super::UiState;

/// Every field of the frame settings by its path and value, read from the settings' data
/// (a field added to them is listed with no edit here), and any of them set by
/// `PATH=VALUE`, as `--set` and the page's `?PATH=VALUE` set it.
pub(super) fn section(ui: &mut egui::Ui, settings: &mut FrameSettings, state: &mut UiState) {
    ui.horizontal(|ui| {
        let typed = ui.add(
            egui::TextEdit::singleline(&mut state.setting_assignment).hint_text("post.bloom=0.05"),
        );
        let entered = typed.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
        if ui.button("Set").clicked() || entered {
            let mut changed = settings.clone();
            match changed.set_assignment(&state.setting_assignment) {
                Ok(()) => {
                    *settings = changed;
                    state.error = None;
                }
                Err(error) => state.error = Some(error.to_string()),
            }
        }
    });
    egui::ScrollArea::vertical()
        .max_height(240.0)
        .show(ui, |ui| {
            egui::Grid::new("every setting")
                .striped(true)
                .show(ui, |ui| {
                    for path in settings.setting_paths() {
                        let value = settings
                            .get(&path)
                            .map(|v| v.to_string())
                            .unwrap_or_default();
                        ui.label(&path);
                        ui.monospace(value);
                        ui.end_row();
                    }
                });
        });
}
