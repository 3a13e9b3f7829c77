//! The egui panels over the frame: parameters (a slider per dimension, playback, blend),
//! camera, gold standard, stats, and lights for a relightable file; and the mouse and keys
//! over the frame itself.

use egui::{Key, Ui};

use pis_play::window::path::PathKind;
use pis_play::window::stats::Shown;
use pis_play::window::view::{CameraMode, ViewState};

use super::lights::LightsPanel;

/// What the panels show besides the state they edit.
pub struct PanelInfo<'a> {
    pub file: &'a str,
    pub adapter: &'a str,
    pub frame_size: (u32, u32),
    pub image_size: (u32, u32),
    /// Samples per pixel the frames are drawn with (multisample antialiasing; 1: none).
    pub msaa: u32,
    pub stats: Shown,
    pub cache_hits: u64,
    pub cache_misses: u64,
    /// Draws of the last frame: surface layers, and reflection terms (environment-map shells).
    pub draws: (u64, u64),
    /// Sample indices of the gold-standard image shown, when one is.
    pub gold: Option<&'a str>,
    /// A gold-standard set was given.
    pub has_gold: bool,
    pub message: Option<&'a str>,
}

/// What the user asked for in this pass that the frame loop must act on.
#[derive(Clone, Copy, Debug, Default, PartialEq)]
pub struct Actions {
    /// The camera mode to switch to (needs the sample camera, which the loop has).
    pub mode: Option<CameraMode>,
    /// Put the free camera back on the sample camera.
    pub reset_free: bool,
    /// Start playing from the current point.
    pub play: bool,
    /// The Lights panel changed the lights: give them to the player.
    pub relight: bool,
}

/// Movement keys held, as −1..1 per axis, and Shift.
pub fn fly_keys(ui: &Ui) -> (f32, f32, f32, bool) {
    ui.input(|i| {
        let axis = |plus: Key, minus: Key| {
            i.key_down(plus) as i32 as f32 - i.key_down(minus) as i32 as f32
        };
        (axis(Key::W, Key::S), axis(Key::D, Key::A), axis(Key::E, Key::Q), i.modifiers.shift)
    })
}

/// Shortcuts: Space play/pause, B blend, C camera mode, G gold standard, H panels.
fn shortcuts(ui: &Ui, v: &mut ViewState, has_gold: bool, actions: &mut Actions) {
    if ui.ctx().egui_wants_keyboard_input() {
        return;
    }
    ui.input(|i| {
        if i.key_pressed(Key::Space) {
            if v.playback.playing {
                v.playback.playing = false;
            } else {
                actions.play = true;
            }
        }
        if i.key_pressed(Key::B) {
            v.multilinear = !v.multilinear;
        }
        if i.key_pressed(Key::C) {
            actions.mode = Some(match v.mode {
                CameraMode::Sample => CameraMode::Orbit,
                CameraMode::Orbit => CameraMode::Fly,
                CameraMode::Fly => CameraMode::Sample,
            });
        }
        if i.key_pressed(Key::G) && has_gold {
            v.show_gold = !v.show_gold;
        }
        if i.key_pressed(Key::H) {
            v.show_ui = !v.show_ui;
        }
    });
}

/// The panels and the frame's own input, for one egui pass over the whole window; the Lights
/// panel where `lights` is given (a relightable file).
pub fn draw(
    ui: &mut Ui,
    v: &mut ViewState,
    info: &PanelInfo,
    lights: Option<&mut LightsPanel>,
    dt: f32,
) -> Actions {
    let mut actions = Actions::default();
    // The frame under the panels: drags and the wheel move the free camera.
    let frame = ui.interact(ui.max_rect(), ui.scope_id().with("frame"), egui::Sense::drag());
    if frame.dragged() {
        let d = frame.drag_delta();
        v.drag(d.x, d.y);
    }
    if frame.hovered() {
        let scroll = ui.input(|i| i.smooth_scroll_delta.y);
        if scroll != 0.0 {
            v.scroll(scroll / 50.0);
        }
    }
    if !ui.ctx().egui_wants_keyboard_input() {
        let (f, r, u, fast) = fly_keys(ui);
        if f != 0.0 || r != 0.0 || u != 0.0 {
            v.fly_keys(f, r, u, dt, fast);
        }
    }
    shortcuts(ui, v, info.has_gold, &mut actions);
    if !v.show_ui {
        return actions;
    }
    let ctx = ui.ctx().clone();
    egui::Window::new("Parameters")
        .default_pos([8.0, 8.0])
        .resizable(false)
        .show(&ctx, |ui| parameters(ui, v, info, &mut actions));
    egui::Window::new("Stats")
        .default_width(180.0)
        .max_width(220.0)
        .anchor(egui::Align2::RIGHT_TOP, [-8.0, 8.0])
        .resizable(false)
        .show(&ctx, |ui| stats(ui, info));
    if let Some(panel) = lights {
        actions.relight = panel.window(&ctx, &v.space, &v.point);
    }
    actions
}

fn parameters(ui: &mut Ui, v: &mut ViewState, info: &PanelInfo, actions: &mut Actions) {
    ui.label(info.file);
    egui::Grid::new("dims").num_columns(2).show(ui, |ui| {
        for (k, axis) in v.space.axes.clone().iter().enumerate() {
            let label = if axis.unit.is_empty() {
                axis.name.clone()
            } else {
                format!("{} ({})", axis.name, axis.unit)
            };
            ui.label(label);
            let s = ui.add_enabled(
                axis.span() > 0.0,
                egui::Slider::new(&mut v.point[k], axis.min..=axis.max),
            );
            if s.changed() {
                v.playback.playing = false;
            }
            ui.label(format!(
                "sample {}/{}",
                axis.nearest_sample(v.point[k]) + 1,
                axis.samples.len()
            ));
            ui.end_row();
        }
    });
    ui.horizontal(|ui| {
        let label = if v.playback.playing { "pause" } else { "play" };
        if ui.button(label).clicked() {
            if v.playback.playing {
                v.playback.playing = false;
            } else {
                actions.play = true;
            }
        }
        let name = |k: PathKind| match k {
            PathKind::Diagonal => "diagonal".to_string(),
            PathKind::Along(d) => {
                format!("along {}", v.space.axes.get(d).map_or("?", |a| a.name.as_str()))
            }
        };
        let mut kind = v.playback.kind;
        egui::ComboBox::from_id_salt("path").selected_text(name(kind)).show_ui(ui, |ui| {
            ui.selectable_value(&mut kind, PathKind::Diagonal, name(PathKind::Diagonal));
            for d in 0..v.space.axes.len() {
                ui.selectable_value(&mut kind, PathKind::Along(d), name(PathKind::Along(d)));
            }
        });
        if kind != v.playback.kind {
            v.playback.kind = kind;
            if v.playback.playing {
                actions.play = true;
            }
        }
    });
    ui.add(
        egui::Slider::new(&mut v.playback.seconds_per_traverse, 1.0..=60.0)
            .logarithmic(true)
            .text("s per traverse"),
    );
    ui.horizontal(|ui| {
        ui.label("blend");
        ui.radio_value(&mut v.multilinear, false, "nearest sample");
        ui.radio_value(&mut v.multilinear, true, "multilinear");
    });
    ui.separator();
    ui.horizontal(|ui| {
        ui.label("camera");
        for (m, name) in
            [(CameraMode::Sample, "sample"), (CameraMode::Orbit, "orbit"), (CameraMode::Fly, "fly")]
        {
            if ui.radio(v.mode == m, name).clicked() {
                actions.mode = Some(m);
            }
        }
    });
    match v.mode {
        CameraMode::Sample => ui.label("the file's camera at the point"),
        CameraMode::Orbit => ui.label("drag: turn around the target · wheel: zoom"),
        CameraMode::Fly => ui.label("WASD: move · Q/E: down/up · Shift: faster · drag: look"),
    };
    if v.mode != CameraMode::Sample && ui.button("back to the sample camera").clicked() {
        actions.reset_free = true;
    }
    if info.has_gold {
        ui.separator();
        ui.checkbox(&mut v.show_gold, "gold standard (ray-traced, nearest sample)");
        if let (true, Some(g)) = (v.show_gold, info.gold) {
            ui.label(format!("ray-traced sample {g}"));
        }
    }
    if let Some(m) = info.message {
        ui.separator();
        ui.colored_label(egui::Color32::from_rgb(255, 120, 100), m);
    }
    ui.small("Space play · B blend · C camera · G gold · H hide panels");
}

fn stats(ui: &mut Ui, info: &PanelInfo) {
    ui.set_max_width(180.0);
    let s = info.stats;
    egui::Grid::new("stats").num_columns(2).show(ui, |ui| {
        let mut row = |k: &str, v: String| {
            ui.label(k);
            ui.label(v);
            ui.end_row();
        };
        row("fps", format!("{:.1}", s.fps));
        // The mean frame and the longest of the last second.
        row("frame, worst", format!("{:.1}, {:.1} ms", s.frame_ms, s.worst_ms));
        row("decode", format!("{:.2} ms", s.decode_ms));
        // Uploads, and the GPU's rebuilds of textures from their level images.
        row("upload, rebuild", format!("{:.1}, {:.1} ms", s.upload_ms, s.rebuild_ms));
        // Frames of the last second that waited for level images to be decoded.
        row("waited", format!("{} of {} frames", s.waited.0, s.waited.1));
        row("cache", format!("{:.1} MB", s.cache_mb));
        row("upload rate", format!("{:.1} MB/s", s.upload_mb_s));
        row("hits / misses", format!("{} / {}", info.cache_hits, info.cache_misses));
        row("draws", format!("{} surface, {} shell", info.draws.0, info.draws.1));
        let (f, t) = (info.frame_size, info.image_size);
        row("size, traced", format!("{}×{}, {}×{}", f.0, f.1, t.0, t.1));
        row("msaa", if info.msaa > 1 { format!("{}×", info.msaa) } else { "off".into() });
    });
    ui.add(egui::Label::new(egui::RichText::new(info.adapter).small()).wrap());
}
