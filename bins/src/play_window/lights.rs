//! The Lights panel, shown for a file with relightable layers (SPEC.md 6.6): the file's own
//! light at the point, or lights of one's own: directional lights (colour, intensity,
//! azimuth and elevation, dots to drag on a hemisphere seen from above) and a sky read from
//! an equirectangular `.exr` or `.hdr` image, turned and scaled. The panel's state turns into
//! the player's lights by [`LightsPanel::lights`].

use egui::{Color32, Pos2, Rect, Sense, Stroke, Ui, Vec2};
use glam::Vec3;
use pis_format::relight::LightDirections;
use pis_play::window::space::Space;
use pis_play::Lights;

use crate::cli::Failure;
use pis_compile::relight::{azimuth_elevation, load_sky, sky_coefficients};

use crate::play::lights::{LightArgs, LightSpec};

/// One directional light of the panel: a colour (linear RGB, 0 to 1) times an intensity,
/// from an azimuth (degrees from +X towards +Z) and elevation (degrees above the horizon).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LightRow {
    pub colour: [f32; 3],
    pub intensity: f32,
    pub azimuth_deg: f32,
    pub elevation_deg: f32,
}

impl LightRow {
    /// A light of `radiance` (colour × intensity) from `direction`: the intensity is the
    /// largest channel, the colour the radiance over it.
    pub fn new(direction: Vec3, radiance: [f32; 3]) -> LightRow {
        let (azimuth_deg, elevation_deg) = azimuth_elevation(direction);
        let intensity = radiance.iter().copied().fold(0.0f32, f32::max);
        let colour =
            if intensity > 0.0 { radiance.map(|c| c / intensity) } else { [1.0, 1.0, 1.0] };
        LightRow { colour, intensity, azimuth_deg, elevation_deg }
    }

    /// A command line's light.
    pub fn from_spec(spec: &LightSpec) -> LightRow {
        let mut row = LightRow::new(Vec3::X, spec.radiance);
        row.azimuth_deg = spec.azimuth_deg;
        row.elevation_deg = spec.elevation_deg;
        row
    }

    /// The light as the command line writes it.
    pub fn spec(&self) -> LightSpec {
        LightSpec {
            azimuth_deg: self.azimuth_deg,
            elevation_deg: self.elevation_deg,
            radiance: self.colour.map(|c| c * self.intensity),
        }
    }
}

/// The panel's sky: the path typed, the image loaded (its path and its projection, unturned),
/// its strength and rotation, and why the last load failed.
#[derive(Clone, Debug, PartialEq)]
pub struct SkyRow {
    pub path: String,
    pub loaded: Option<(String, Vec<[f64; 3]>)>,
    pub strength: f32,
    pub rotation_deg: f32,
    pub error: Option<String>,
}

impl Default for SkyRow {
    fn default() -> Self {
        SkyRow { path: String::new(), loaded: None, strength: 1.0, rotation_deg: 0.0, error: None }
    }
}

/// The Lights panel's state.
#[derive(Clone, Debug, PartialEq)]
pub struct LightsPanel {
    /// The file's own light at the point (else the lights and sky below).
    pub own: bool,
    pub lights: Vec<LightRow>,
    pub sky: SkyRow,
    /// The file's light directions and traced radiance E₀.
    pub file: LightDirections,
}

impl LightsPanel {
    /// The panel for a file's light directions `file`, at `point` of `space`: the command
    /// line's lights and sky where given (the sky read now), else the file's own light, with
    /// one light of the list where the file's light is at the point.
    pub fn new(
        file: &LightDirections,
        space: &Space,
        point: &[f32],
        args: &LightArgs,
    ) -> Result<LightsPanel, Failure> {
        let mut panel = LightsPanel {
            own: !args.given(),
            lights: Vec::new(),
            sky: SkyRow::default(),
            file: file.clone(),
        };
        if args.given() {
            panel.lights = args.lights.iter().map(LightRow::from_spec).collect();
            if let (Some(path), Some(s)) = (&args.sky, args.read_sky()?) {
                let path = path.display().to_string();
                panel.sky.path = path.clone();
                panel.sky.loaded = Some((path, s));
            }
            panel.sky.strength = args.sky_strength;
            panel.sky.rotation_deg = args.sky_rotation;
        } else if let Some(d) = traced_direction(file, space, point) {
            panel.lights.push(LightRow::new(Vec3::from(d), file.radiance));
        }
        Ok(panel)
    }

    /// The player's lights: none for the file's own light, else exactly the panel's lights
    /// and sky.
    pub fn lights(&self) -> Option<Lights> {
        (!self.own).then(|| self.listed())
    }

    /// The panel's lights and sky, whichever is shown.
    fn listed(&self) -> Lights {
        Lights {
            directional: self.lights.iter().map(|l| l.spec().light()).collect(),
            sky: self
                .sky
                .loaded
                .as_ref()
                .map(|(_, s)| sky_coefficients(s, self.sky.rotation_deg, self.sky.strength)),
        }
    }

    /// Editing the lights or the sky (from the panel `was`) while the file's light is shown
    /// shows the panel's lights.
    fn follow_edits(&mut self, was: &LightsPanel) {
        if self.own && was.own && self.listed() != was.listed() {
            self.own = false;
        }
    }

    /// A light added by the panel's button: the file's traced colour and intensity, from
    /// 45° up, a quarter turn from the last light.
    fn added(&self) -> LightRow {
        let mut row = LightRow::new(Vec3::X, self.file.radiance);
        row.elevation_deg = 45.0;
        row.azimuth_deg = self.lights.last().map_or(0.0, |l| wrap_degrees(l.azimuth_deg + 90.0));
        row
    }

    /// The panel in its own window (at first collapsed where the file's own light is shown).
    /// `point` is the parameter point (the file's light shown on the hemisphere is the one at
    /// its nearest sample). Returns whether the lights changed.
    pub fn window(&mut self, ctx: &egui::Context, space: &Space, point: &[f32]) -> bool {
        let before = self.lights();
        let traced_here = traced_direction(&self.file, space, point);
        egui::Window::new("Lights")
            .pivot(egui::Align2::LEFT_BOTTOM)
            .default_pos([8.0, ctx.content_rect().bottom() - 8.0])
            .default_open(!self.own)
            .resizable(false)
            .show(ctx, |ui| self.ui(ui, traced_here));
        self.lights() != before
    }

    fn ui(&mut self, ui: &mut Ui, traced_here: Option<[f32; 3]>) {
        let was = self.clone();
        ui.horizontal(|ui| {
            ui.radio_value(&mut self.own, true, "the file's light");
            ui.radio_value(&mut self.own, false, "these lights");
        });
        hemisphere(ui, &mut self.lights, &self.file.directions, traced_here.filter(|_| self.own));
        self.light_rows(ui);
        ui.separator();
        self.sky_row(ui);
        ui.small(
            "grey: the file's light directions (ring: at the point) · drag a dot to move its light",
        );
        self.follow_edits(&was);
    }

    fn light_rows(&mut self, ui: &mut Ui) {
        let mut remove = None;
        let speed = self.file.radiance.iter().copied().fold(0.0f32, f32::max).max(1e-3) / 100.0;
        egui::Grid::new("lights").num_columns(5).show(ui, |ui| {
            for (i, l) in self.lights.iter_mut().enumerate() {
                egui::color_picker::color_edit_button_rgb(ui, &mut l.colour)
                    .on_hover_text("colour (linear RGB)");
                ui.add(egui::DragValue::new(&mut l.intensity).range(0.0..=1e6).speed(speed))
                    .on_hover_text("intensity, in the units of the file's traced light");
                ui.add(
                    egui::Slider::new(&mut l.azimuth_deg, -180.0..=180.0).text("az").suffix("°"),
                )
                .on_hover_text("azimuth: degrees from +X towards +Z");
                ui.add(
                    egui::Slider::new(&mut l.elevation_deg, -90.0..=90.0).text("el").suffix("°"),
                )
                .on_hover_text("elevation: degrees above the horizon");
                if ui.button("remove").clicked() {
                    remove = Some(i);
                }
                ui.end_row();
            }
        });
        if let Some(i) = remove {
            self.lights.remove(i);
        }
        if ui.button("add light").clicked() {
            self.lights.push(self.added());
        }
    }

    fn sky_row(&mut self, ui: &mut Ui) {
        let sky = &mut self.sky;
        ui.horizontal(|ui| {
            ui.label("sky");
            let field = ui.add(
                egui::TextEdit::singleline(&mut sky.path)
                    .hint_text("an equirectangular .exr or .hdr")
                    .desired_width(220.0),
            );
            let entered = field.lost_focus() && ui.input(|i| i.key_pressed(egui::Key::Enter));
            if ui.button("load").clicked() || entered {
                let path = sky.path.trim().to_string();
                match load_sky(std::path::Path::new(&path)) {
                    Ok(s) => {
                        sky.loaded = Some((path, s));
                        sky.error = None;
                    }
                    Err(e) => sky.error = Some(e),
                }
            }
            if sky.loaded.is_some() && ui.button("remove").clicked() {
                sky.loaded = None;
            }
        });
        if let Some((path, _)) = &sky.loaded {
            ui.label(format!("sky: {path}"));
        }
        ui.add_enabled_ui(sky.loaded.is_some(), |ui| {
            ui.add(
                egui::Slider::new(&mut sky.strength, 0.0..=16.0)
                    .logarithmic(true)
                    .clamping(egui::SliderClamping::Never)
                    .text("strength"),
            );
            ui.add(
                egui::Slider::new(&mut sky.rotation_deg, -180.0..=180.0)
                    .suffix("°")
                    .text("rotation about +Y"),
            );
        });
        if let Some(e) = &sky.error {
            ui.colored_label(Color32::from_rgb(255, 120, 100), e);
        }
    }
}

/// The file's light direction at the sample of `point` nearest along its light dimension.
pub fn traced_direction(file: &LightDirections, space: &Space, point: &[f32]) -> Option<[f32; 3]> {
    let axis = space.axes.get(file.dim)?;
    let value = *point.get(file.dim)?;
    file.directions.get(axis.nearest_sample(value)).copied()
}

/// An angle in degrees brought into −180 to 180.
fn wrap_degrees(a: f32) -> f32 {
    (a + 180.0).rem_euclid(360.0) - 180.0
}

/// Where a direction lies on the hemisphere seen from above, the horizon at radius 1: the
/// radius is (90° − elevation)/90°, the angle the azimuth (+X right, +Z down the screen, as
/// seen from +Y); below the horizon it stays on the rim.
pub fn disc_position(azimuth_deg: f32, elevation_deg: f32) -> Vec2 {
    let r = ((90.0 - elevation_deg) / 90.0).clamp(0.0, 1.0);
    let (sin, cos) = azimuth_deg.to_radians().sin_cos();
    Vec2::new(r * cos, r * sin)
}

/// The azimuth and elevation of a point of the disc ([`disc_position`] undone; outside the
/// rim, the horizon). At the centre the azimuth is `azimuth_deg`, unchanged.
pub fn disc_direction(p: Vec2, azimuth_deg: f32) -> (f32, f32) {
    let r = p.length().min(1.0);
    let azimuth = if r < 1e-4 { azimuth_deg } else { p.y.atan2(p.x).to_degrees() };
    (azimuth, 90.0 - 90.0 * r)
}

/// A light's colour on screen: its colour at full brightness (the largest channel 1).
fn dot_colour(l: &LightRow) -> Color32 {
    let m = l.colour.iter().copied().fold(0.0f32, f32::max);
    let c = if m > 0.0 { l.colour.map(|c| c / m) } else { [0.0; 3] };
    Color32::from(egui::Rgba::from_rgb(c[0], c[1], c[2]))
}

/// The hemisphere seen from above: rings every 30° of elevation, the file's light
/// directions as grey dots (`here`, the file's light at the point, ringed) and the lights as
/// dots that drag to new directions. Returns where the disc was drawn: its centre and the
/// horizon's radius.
fn hemisphere(
    ui: &mut Ui,
    lights: &mut [LightRow],
    traced: &[[f32; 3]],
    here: Option<[f32; 3]>,
) -> (Pos2, f32) {
    let side = 170.0;
    let (rect, _) = ui.allocate_exact_size(Vec2::splat(side), Sense::hover());
    let centre = rect.center();
    let radius = side / 2.0 - 16.0;
    let at = |az: f32, el: f32| centre + disc_position(az, el) * radius;
    let painter = ui.painter_at(rect);
    let faint = Stroke::new(1.0, Color32::from_gray(90));
    painter.circle_filled(centre, radius, Color32::from_gray(24));
    for el in [30.0, 60.0] {
        painter.circle_stroke(centre, radius * (90.0 - el) / 90.0, faint);
    }
    painter.circle_stroke(centre, radius, Stroke::new(1.0, Color32::from_gray(140)));
    painter.line_segment([centre - Vec2::X * radius, centre + Vec2::X * radius], faint);
    painter.line_segment([centre - Vec2::Y * radius, centre + Vec2::Y * radius], faint);
    let font = egui::FontId::proportional(11.0);
    let label = |p: Pos2, text: &str| {
        painter.text(p, egui::Align2::CENTER_CENTER, text, font.clone(), Color32::GRAY)
    };
    label(centre + Vec2::X * (radius + 7.0), "+X");
    label(centre + Vec2::Y * (radius + 7.0), "+Z");
    for d in traced {
        let (az, el) = azimuth_elevation(Vec3::from(*d));
        if el >= 0.0 {
            painter.circle_filled(at(az, el), 1.5, Color32::from_gray(120));
        }
    }
    if let Some(d) = here {
        let (az, el) = azimuth_elevation(Vec3::from(d));
        painter.circle_stroke(at(az, el), 5.0, Stroke::new(1.5, Color32::from_gray(200)));
    }
    let id = ui.scope_id().with("hemisphere");
    for (i, l) in lights.iter_mut().enumerate() {
        let p = at(l.azimuth_deg, l.elevation_deg);
        let dot =
            ui.interact(Rect::from_center_size(p, Vec2::splat(14.0)), id.with(i), Sense::drag());
        if let (true, Some(pointer)) = (dot.dragged(), dot.interact_pointer_pos()) {
            let (az, el) = disc_direction((pointer - centre) / radius, l.azimuth_deg);
            (l.azimuth_deg, l.elevation_deg) = (az, el);
        }
        let p = at(l.azimuth_deg, l.elevation_deg);
        let below = l.elevation_deg < 0.0;
        let ring =
            if dot.hovered() || dot.dragged() { Color32::WHITE } else { Color32::from_gray(170) };
        if below {
            painter.circle_stroke(p, 5.0, Stroke::new(2.0, dot_colour(l)));
        } else {
            painter.circle_filled(p, 5.0, dot_colour(l));
        }
        painter.circle_stroke(p, 6.0, Stroke::new(1.0, ring));
        painter.text(
            p + Vec2::new(8.0, -8.0),
            egui::Align2::LEFT_BOTTOM,
            (i + 1).to_string(),
            egui::FontId::proportional(10.0),
            Color32::from_gray(210),
        );
    }
    (centre, radius)
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::play::lights::parse_light;
    use pis_compile::relight::direction_at;
    use pis_format::{Dimension, DimensionKind};

    fn file() -> LightDirections {
        LightDirections {
            dim: 0,
            radiance: [3.0, 2.0, 1.0],
            directions: vec![[0.0, 1.0, 0.0], [1.0, 0.0, 0.0], [0.0, 0.0, 1.0]],
        }
    }

    fn close(a: Vec3, b: Vec3) -> bool {
        (a - b).length() < 1e-5
    }

    #[test]
    fn a_row_is_its_colour_times_its_intensity() {
        let spec = parse_light("-120,30,0.7,0.9,1.5").unwrap();
        let row = LightRow::from_spec(&spec);
        assert_eq!((row.intensity, row.azimuth_deg, row.elevation_deg), (1.5, -120.0, 30.0));
        assert!((row.colour[2] - 1.0).abs() < 1e-6 && (row.colour[0] - 0.7 / 1.5).abs() < 1e-6);
        let back = row.spec();
        for ch in 0..3 {
            assert!((back.radiance[ch] - spec.radiance[ch]).abs() < 1e-6);
        }
        let dark = LightRow::new(Vec3::Y, [0.0; 3]);
        assert_eq!((dark.colour, dark.intensity, dark.elevation_deg), ([1.0; 3], 0.0, 90.0));
    }

    #[test]
    fn the_panel_gives_the_files_light_or_exactly_its_own() {
        let sky = vec![[1.0, 2.0, 3.0]; 4];
        let mut panel = LightsPanel {
            own: true,
            lights: vec![LightRow::from_spec(&parse_light("90,0,2,2,2").unwrap())],
            sky: SkyRow { loaded: Some(("sky.hdr".into(), sky.clone())), ..SkyRow::default() },
            file: file(),
        };
        assert_eq!(panel.lights(), None);
        panel.own = false;
        panel.sky.strength = 2.0;
        let lights = panel.lights().unwrap();
        assert_eq!(lights.directional.len(), 1);
        assert!(close(lights.directional[0].direction, Vec3::Z));
        assert_eq!(lights.directional[0].radiance, [2.0, 2.0, 2.0]);
        assert_eq!(lights.sky, Some(sky_coefficients(&sky, 0.0, 2.0)));
        panel.sky.rotation_deg = 90.0;
        assert_eq!(panel.lights().unwrap().sky, Some(sky_coefficients(&sky, 90.0, 2.0)));
        panel.lights.clear();
        panel.sky.loaded = None;
        assert_eq!(panel.lights(), Some(Lights::default()), "no lights: darkness");
        // An edit while the file's light is shown shows the panel's lights; a sky setting
        // without a sky, or a choice of the file's light, does not.
        panel.own = true;
        let was = panel.clone();
        panel.sky.strength = 3.0;
        panel.follow_edits(&was);
        assert!(panel.own);
        panel.lights.push(LightRow::new(Vec3::Y, [1.0; 3]));
        panel.follow_edits(&was);
        assert!(!panel.own);
        let was = LightsPanel { own: false, ..panel.clone() };
        panel.own = true;
        panel.follow_edits(&was);
        assert!(panel.own);
    }

    #[test]
    fn the_panel_starts_from_the_command_line_or_the_files_light_at_the_point() {
        let dim = Dimension {
            name: "light".into(),
            kind: DimensionKind::Light,
            periodic: false,
            unit: String::new(),
            block_size: 4,
            values: vec![0.0, 1.0, 2.0],
        };
        let space = Space::new(&[dim]);
        let panel = LightsPanel::new(&file(), &space, &[1.2], &LightArgs::default()).unwrap();
        assert!(panel.own && panel.lights.len() == 1 && panel.sky.loaded.is_none());
        let l = panel.lights[0];
        assert!(close(direction_at(l.azimuth_deg, l.elevation_deg), Vec3::X));
        assert_eq!(l.spec().radiance, [3.0, 2.0, 1.0]);
        assert_eq!(traced_direction(&file(), &space, &[1.7]), Some([0.0, 0.0, 1.0]));
        let args = LightArgs {
            lights: vec![parse_light("40,50,2.5,1.9,1.2").unwrap()],
            ..LightArgs::default()
        };
        let panel = LightsPanel::new(&file(), &space, &[0.0], &args).unwrap();
        assert!(!panel.own);
        assert_eq!(panel.lights(), args.relight(std::path::Path::new("f.pis"), true).unwrap());
        let added = panel.added();
        assert_eq!((added.azimuth_deg, added.elevation_deg, added.intensity), (130.0, 45.0, 3.0));
    }

    #[test]
    fn dragging_a_dot_turns_its_light() {
        let ctx = egui::Context::default();
        // On the horizon towards +X: the disc's right edge.
        let mut lights = vec![LightRow::new(Vec3::X, [1.0; 3]), LightRow::new(Vec3::Y, [1.0; 3])];
        let traced = file().directions;
        let frame = |events: Vec<egui::Event>, lights: &mut Vec<LightRow>| {
            let input = egui::RawInput {
                events,
                screen_rect: Some(Rect::from_min_size(Pos2::ZERO, Vec2::splat(400.0))),
                ..Default::default()
            };
            let mut disc = (Pos2::ZERO, 0.0);
            let out = ctx.run_ui(input, |ui| disc = hemisphere(ui, lights, &traced, None));
            out.drop_without_applying_deltas();
            disc
        };
        let (centre, radius) = frame(vec![], &mut lights);
        let (from, to) = (centre + Vec2::X * radius, centre + Vec2::Y * radius / 2.0);
        let button = |pos, pressed| egui::Event::PointerButton {
            pos,
            button: egui::PointerButton::Primary,
            pressed,
            modifiers: egui::Modifiers::NONE,
        };
        for events in [
            vec![egui::Event::PointerMoved(from)],
            vec![button(from, true)],
            vec![egui::Event::PointerMoved(from.lerp(to, 0.5))],
            vec![egui::Event::PointerMoved(to)],
            vec![button(to, false)],
        ] {
            frame(events, &mut lights);
        }
        let l = lights[0];
        assert!(
            (l.azimuth_deg - 90.0).abs() < 0.5 && (l.elevation_deg - 45.0).abs() < 0.5,
            "{l:?}"
        );
        assert_eq!(lights[1].elevation_deg, 90.0, "the other light stays");
    }

    #[test]
    fn the_hemisphere_is_seen_from_above() {
        // Straight up at the centre, the horizon on the rim; +X right, +Z down the screen.
        assert!(disc_position(10.0, 90.0).length() < 1e-6);
        assert!((disc_position(0.0, 0.0) - Vec2::X).length() < 1e-6);
        assert!((disc_position(90.0, 0.0) - Vec2::Y).length() < 1e-6);
        assert!((disc_position(180.0, 45.0) - Vec2::new(-0.5, 0.0)).length() < 1e-6);
        assert!((disc_position(0.0, -30.0) - Vec2::X).length() < 1e-6, "below: on the rim");
        for (az, el) in [(40.0, 50.0), (-120.0, 30.0), (170.0, 5.0)] {
            let (a, e) = disc_direction(disc_position(az, el), 0.0);
            assert!((a - az).abs() < 1e-3 && (e - el).abs() < 1e-3, "{az} {el}: {a} {e}");
        }
        assert_eq!(disc_direction(Vec2::ZERO, 33.0), (33.0, 90.0));
        assert_eq!(disc_direction(Vec2::new(0.0, 2.0), 0.0), (90.0, 0.0));
        assert_eq!(wrap_degrees(190.0), -170.0);
    }
}
