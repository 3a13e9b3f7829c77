//! The window: a winit application whose every frame is the player's frame drawn straight
//! into the window's surface texture (an sRGB view, so the hardware encodes the player's
//! linear radiance), with the egui panels drawn over it in a second pass.
//!
//! Drawing into the surface, rather than into an offscreen texture that egui shows, keeps
//! the player's frame at the window's own resolution with no extra copy or resampling: the
//! pixels on screen are the pixels the player drew, as `render_image` would read them back.

use std::path::PathBuf;
use std::sync::Arc;
use std::time::{Duration, Instant};

use pis_play::{FrameStats, Gpu, GpuOptions, Player, PlayerOptions};
use winit::application::ApplicationHandler;
use winit::event::{StartCause, WindowEvent};
use winit::event_loop::{ActiveEventLoop, ControlFlow, EventLoop};
use winit::window::{Window, WindowId};

use super::gold::GoldSet;
use super::lights::LightsPanel;
use super::screenshot::{write_png_rgba8, Capture};
use super::surface::WindowSurface;
use super::ui::{self, PanelInfo};
use crate::cli::{Exit, Failure};
use crate::play::lights::LightArgs;
use pis_eval::headless::play_failure;
use pis_play::window::camera::sight_convergence;
use pis_play::window::path::{PathKind, Playback};
use pis_play::window::space::Space;
use pis_play::window::stats::{FrameSample, StatsMeter};
use pis_play::window::view::ViewState;

/// How the window is opened and run.
#[derive(Clone, Debug)]
pub struct WindowOptions {
    pub file: PathBuf,
    /// Window (and frame) size in pixels; default the file's image size, scaled up by a whole
    /// factor to at least 640 pixels wide.
    pub size: Option<(u32, u32)>,
    /// A ray-traced set of the same space, for the gold-standard toggle.
    pub set: Option<PathBuf>,
    /// Save frame number `frames` as PNG here, then exit.
    pub screenshot: Option<PathBuf>,
    /// Exit after this many frames (with a report of the frame rate); with `screenshot`, the
    /// frame saved.
    pub frames: Option<u32>,
    /// The starting point; default the middle sample of every dimension.
    pub at: Option<Vec<f32>>,
    /// Start with playback running along the diagonal.
    pub play: bool,
    /// Start with the free orbit camera (at the sample camera).
    pub orbit: bool,
    /// Start with multilinear blending between samples (else the nearest sample).
    pub multilinear: bool,
    /// Start with the panels hidden (H shows them).
    pub hide_ui: bool,
    /// Start showing the gold standard (needs `set`).
    pub show_gold: bool,
    /// Wait for the display's refresh between frames (off to measure drawing speed).
    pub vsync: bool,
    pub gpu: GpuOptions,
    pub player: PlayerOptions,
    /// The lights to start with (a relightable file; none given: the file's own light).
    pub lights: LightArgs,
}

/// What a run with `frames` measured, printed at exit.
#[derive(Clone, Copy, Debug, Default, PartialEq, serde::Serialize)]
pub struct RunReport {
    pub frames: u32,
    pub seconds: f64,
    /// Frames per second over the run, the first frame (opening, first decodes) left out.
    pub fps: f64,
    /// Mean of the player's FrameStats over the same frames.
    pub frame_ms: f64,
    pub decode_ms: f64,
    pub upload_ms: f64,
    pub rebuild_ms: f64,
    pub frame_size: [u32; 2],
    /// Samples per pixel drawn with (multisample antialiasing; 1: none).
    pub msaa_samples: u32,
    /// Samples per pixel asked for (`--msaa`).
    pub msaa_requested: u32,
}

/// Why a window run ended without success.
#[derive(Debug)]
pub enum WindowFailure {
    /// No display could be connected to: nothing was opened (a caller may draw headless).
    NoDisplay(String),
    /// The window ran and failed.
    Failed(Failure),
}

impl From<Failure> for WindowFailure {
    fn from(f: Failure) -> Self {
        WindowFailure::Failed(f)
    }
}

impl From<WindowFailure> for Failure {
    fn from(w: WindowFailure) -> Self {
        match w {
            WindowFailure::NoDisplay(m) => Failure::new(Exit::Runtime, anyhow::anyhow!("{m}")),
            WindowFailure::Failed(f) => f,
        }
    }
}

/// Opens the window and runs it until it is closed (or `frames` frames were drawn).
pub fn run_window(opts: WindowOptions) -> Result<Option<RunReport>, WindowFailure> {
    // The instance first: it gives the process an XDG_RUNTIME_DIR where none is set, before
    // the event loop or any driver thread reads the environment.
    let instance = Gpu::instance();
    let event_loop = EventLoop::new().map_err(|e| {
        WindowFailure::NoDisplay(format!("cannot open a window: {e} (set DISPLAY or WAYLAND_DISPLAY to a running display, or run under `xvfb-run -a`)"))
    })?;
    let mut app = App { instance, opts, running: None, failure: None, report: None };
    event_loop
        .run_app(&mut app)
        .map_err(|e| Failure::new(Exit::Runtime, anyhow::anyhow!("window event loop: {e}")))?;
    match app.failure {
        Some(f) => Err(f.into()),
        None => Ok(app.report),
    }
}

struct App {
    instance: wgpu::Instance,
    opts: WindowOptions,
    running: Option<Running>,
    failure: Option<Failure>,
    report: Option<RunReport>,
}

struct GoldTexture {
    index: usize,
    texture: egui::TextureHandle,
    size: (u32, u32),
    label: String,
}

struct Running {
    window: Arc<Window>,
    gpu: Arc<Gpu>,
    surface: WindowSurface,
    player: Player,
    egui_ctx: egui::Context,
    egui_state: egui_winit::State,
    renderer: egui_wgpu::Renderer,
    view: ViewState,
    meter: StatsMeter,
    gold: Option<GoldSet>,
    gold_texture: Option<GoldTexture>,
    /// The Lights panel, for a relightable file.
    lights: Option<LightsPanel>,
    file_label: String,
    adapter: String,
    message: Option<String>,
    last_stats: FrameStats,
    started: Instant,
    last: Instant,
    /// Frames presented.
    frames: u32,
    /// Sums over frames 2.. for the run report.
    sum: (f64, f64, f64, f64),
    second_frame_at: Option<Instant>,
    /// Something moves (playback, held keys, a drag): draw again at once.
    active: bool,
    repaint_after: Option<Duration>,
}

fn runtime(e: impl std::fmt::Display) -> Failure {
    Failure::new(Exit::Runtime, anyhow::anyhow!("{e}"))
}

/// The default window size for an image of `w × h`: scaled by a whole factor to at least
/// 640 pixels wide.
pub fn default_window_size((w, h): (u32, u32)) -> (u32, u32) {
    let (w, h) = (w.max(1), h.max(1));
    let k = 640u32.div_ceil(w).max(1);
    (w * k, h * k)
}

impl App {
    fn start(&mut self, event_loop: &ActiveEventLoop) -> Result<Running, Failure> {
        let o = &self.opts;
        let probe_size = match o.size {
            Some(s) => s,
            None => {
                // The file's image size decides the window's: read it without a GPU.
                let reader = pis_format::PisReader::open(&o.file).map_err(Failure::from)?;
                let c = &reader.container().cameras;
                default_window_size((c.width, c.height))
            }
        };
        let name = o
            .file
            .file_name()
            .map_or_else(|| o.file.display().to_string(), |n| n.to_string_lossy().into_owned());
        let attrs = Window::default_attributes()
            .with_title(format!("pis-play — {name}"))
            .with_inner_size(winit::dpi::PhysicalSize::new(probe_size.0, probe_size.1));
        let window = Arc::new(
            event_loop
                .create_window(attrs)
                .map_err(|e| runtime(format!("cannot open a window: {e}")))?,
        );
        let surface = self
            .instance
            .create_surface(window.clone())
            .map_err(|e| runtime(format!("cannot make a wgpu surface for the window: {e}")))?;
        let (gpu, caps) =
            Gpu::for_surface(&self.instance, &surface, o.gpu).map_err(play_failure)?;
        let gpu = Arc::new(gpu);
        let surface =
            WindowSurface::new(surface, caps, &gpu.device, &window, o.vsync).map_err(runtime)?;
        let mut player =
            Player::open(gpu.clone(), &o.file, o.player.clone()).map_err(play_failure)?;
        if let Some(note) = &player.multisample_for(surface.view_format).note {
            eprintln!("pis-play: note: {note}");
        }

        let space = Space::new(player.dimensions());
        let point = match &o.at {
            Some(at) if at.len() == space.axes.len() => at.clone(),
            Some(at) => {
                let names: Vec<&str> = space.axes.iter().map(|a| a.name.as_str()).collect();
                return Err(Failure::new(
                    Exit::Usage,
                    anyhow::anyhow!(
                        "--at has {} values, the file's space has {} dimensions ({})",
                        at.len(),
                        names.len(),
                        names.join(", ")
                    ),
                ));
            }
            None => space.start_point(),
        };
        let focus = focus_distance(&player, &space, &point);
        let mut view = ViewState::new(space, point, focus);
        view.show_ui = !o.hide_ui;
        view.multilinear = o.multilinear;
        view.show_gold = o.show_gold && o.set.is_some();
        if o.orbit {
            let sample = player.sample_camera(&view.draw_point());
            view.set_mode(pis_play::window::view::CameraMode::Orbit, &sample);
        }
        if o.play {
            view.playback = Playback::new(PathKind::Diagonal);
            view.playback.play_from(&view.space, &view.point);
        }
        let gold = match &o.set {
            Some(dir) => Some(GoldSet::open(dir, player.dimensions())?),
            None => None,
        };
        o.lights.check(&o.file, player.light_directions().is_some())?;
        let lights = match player.light_directions() {
            Some(file) => Some(LightsPanel::new(file, &view.space, &view.point, &o.lights)?),
            None => None,
        };
        if let Some(panel) = &lights {
            player.set_lights(panel.lights()).map_err(play_failure)?;
        }

        let egui_ctx = egui::Context::default();
        let max_side = gpu.limits.max_texture_dimension_2d as usize;
        let egui_state = egui_winit::State::new(
            egui_ctx.clone(),
            egui::ViewportId::ROOT,
            &window,
            Some(window.scale_factor() as f32),
            window.theme(),
            Some(max_side),
        );
        let renderer = egui_wgpu::Renderer::new(
            &gpu.device,
            surface.view_format,
            egui_wgpu::RendererOptions { dithering: false, ..Default::default() },
        );
        let now = Instant::now();
        Ok(Running {
            adapter: gpu.describe(),
            window,
            gpu,
            surface,
            player,
            egui_ctx,
            egui_state,
            renderer,
            view,
            meter: StatsMeter::new(1.0, 0.1),
            gold,
            gold_texture: None,
            lights,
            file_label: o.file.display().to_string(),
            message: None,
            last_stats: FrameStats::default(),
            started: now,
            last: now,
            frames: 0,
            sum: (0.0, 0.0, 0.0, 0.0),
            second_frame_at: None,
            active: true,
            repaint_after: None,
        })
    }

    fn fail(&mut self, event_loop: &ActiveEventLoop, f: Failure) {
        self.failure = Some(f);
        event_loop.exit();
    }
}

/// How far ahead of the sample cameras the scene is: where their lines of sight meet, seen
/// from the camera at `point`; else the geometric mean of the near and far planes.
fn focus_distance(player: &Player, space: &Space, point: &[f32]) -> f32 {
    let here = player.sample_camera(point);
    let mut cams = Vec::new();
    for (k, axis) in space.axes.iter().enumerate() {
        for &v in &axis.samples {
            let mut p = point.to_vec();
            p[k] = v;
            cams.push(player.sample_camera(&p));
        }
    }
    let ahead = sight_convergence(&cams)
        .map(|c| (c - here.eye).dot((here.target - here.eye).normalize_or_zero()));
    match ahead {
        Some(d) if d.is_finite() && d > 2.0 * here.near => d,
        _ if here.far.is_finite() => (here.near * here.far).sqrt(),
        _ => 100.0 * here.near,
    }
}

impl ApplicationHandler for App {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.running.is_some() {
            return;
        }
        match self.start(event_loop) {
            Ok(r) => {
                r.window.request_redraw();
                self.running = Some(r);
            }
            Err(f) => self.fail(event_loop, f),
        }
    }

    fn new_events(&mut self, _: &ActiveEventLoop, cause: StartCause) {
        if let (StartCause::ResumeTimeReached { .. }, Some(r)) = (cause, &self.running) {
            r.window.request_redraw();
        }
    }

    fn window_event(&mut self, event_loop: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        let Some(r) = self.running.as_mut() else { return };
        let response = r.egui_state.on_window_event(&r.window, &event);
        match event {
            WindowEvent::CloseRequested => event_loop.exit(),
            WindowEvent::Resized(size) => {
                r.surface.resize(&r.gpu.device, size.width, size.height);
                r.window.request_redraw();
            }
            WindowEvent::RedrawRequested => match r.redraw(&self.opts) {
                Ok(Some(report)) => {
                    self.report = Some(report);
                    event_loop.exit();
                }
                Ok(None) => {}
                Err(f) => self.fail(event_loop, f),
            },
            _ => {
                if response.repaint {
                    r.window.request_redraw();
                }
            }
        }
    }

    fn about_to_wait(&mut self, event_loop: &ActiveEventLoop) {
        let Some(r) = self.running.as_ref() else { return };
        if r.active || self.opts.frames.is_some() {
            event_loop.set_control_flow(ControlFlow::Poll);
            r.window.request_redraw();
        } else if let Some(d) = r.repaint_after {
            event_loop.set_control_flow(ControlFlow::WaitUntil(Instant::now() + d));
        } else {
            event_loop.set_control_flow(ControlFlow::Wait);
        }
    }
}

impl Running {
    /// Draws and presents one frame. Returns the run report when the run is over.
    fn redraw(&mut self, opts: &WindowOptions) -> Result<Option<RunReport>, Failure> {
        let now = Instant::now();
        let dt = (now - self.last).as_secs_f32().min(0.25);
        self.last = now;
        if self.view.playback.playing {
            let p = self.view.point.clone();
            self.view.point = self.view.playback.advance(&self.view.space, &p, dt);
        }
        // The next samples along the path decode while this frame draws.
        self.player.prefetch(&self.view.ahead(2));
        self.load_gold();

        let size = self.surface.size();
        let shown = self.meter.shown();
        let gold_label =
            self.gold_texture.as_ref().filter(|_| self.view.show_gold).map(|g| g.label.clone());
        let info = PanelInfo {
            file: &self.file_label,
            adapter: &self.adapter,
            frame_size: size,
            image_size: self.player.image_size(),
            msaa: self.player.multisample_for(self.surface.view_format).samples,
            stats: shown,
            cache_hits: self.last_stats.cache_hits,
            cache_misses: self.last_stats.cache_misses,
            draws: (self.last_stats.surface_draws, self.last_stats.shell_draws),
            gold: gold_label.as_deref(),
            has_gold: self.gold.is_some(),
            message: self.message.as_deref(),
        };
        let input = self.egui_state.take_egui_input(&self.window);
        let mut actions = ui::Actions::default();
        let mut relight = false;
        let mut active = false;
        let view = &mut self.view;
        let mut lights = self.lights.as_mut();
        let gold =
            self.gold_texture.as_ref().filter(|_| view.show_gold).map(|g| (g.texture.id(), g.size));
        let mut full = self.egui_ctx.run_ui(input, |ui| {
            if let Some((id, (w, h))) = gold {
                paint_gold(ui, id, w, h);
            }
            actions = ui::draw(ui, view, &info, lights.as_deref_mut(), dt);
            // A change in any pass of the frame relights it.
            relight |= actions.relight;
            active = ui.input(|i| !i.keys_down.is_empty() || i.pointer.any_down());
        });
        self.active = active || self.view.playback.playing || actions.play;
        let sample = self.player.sample_camera(&self.view.draw_point());
        if let Some(m) = actions.mode {
            self.view.set_mode(m, &sample);
        }
        if actions.reset_free {
            self.view.reset_free(&sample);
        }
        if actions.play {
            self.view.playback.play_from(&self.view.space, &self.view.point);
        }
        if let (true, Some(panel)) = (relight, &self.lights) {
            self.player.set_lights(panel.lights()).map_err(play_failure)?;
            self.window.request_redraw();
        }
        self.repaint_after = full
            .viewport_output
            .get(&egui::ViewportId::ROOT)
            .map(|v| v.repaint_delay)
            .filter(|d| *d < Duration::from_secs(3600));
        self.egui_state.handle_platform_output(&self.window, full.platform_output);
        let primitives = self.egui_ctx.tessellate(full.shapes, full.pixels_per_point);
        let screen = egui_wgpu::ScreenDescriptor {
            size_in_pixels: [size.0, size.1],
            pixels_per_point: full.pixels_per_point,
        };
        // egui's texture changes: uploaded now, whether or not the surface gives a frame, and
        // freed after the frame.
        let frees = std::mem::take(&mut full.textures_delta.free);
        for (id, deltas) in std::mem::take(&mut full.textures_delta.set) {
            for delta in &deltas {
                self.renderer.update_texture(&self.gpu.device, &self.gpu.queue, id, delta);
            }
        }

        let frame = match self.surface.surface.get_current_texture() {
            wgpu::CurrentSurfaceTexture::Success(t) => t,
            wgpu::CurrentSurfaceTexture::Suboptimal(t) => {
                self.surface.reconfigure(&self.gpu.device);
                t
            }
            wgpu::CurrentSurfaceTexture::Timeout | wgpu::CurrentSurfaceTexture::Occluded => {
                self.free_textures(&frees);
                self.window.request_redraw();
                return Ok(None);
            }
            wgpu::CurrentSurfaceTexture::Outdated | wgpu::CurrentSurfaceTexture::Lost => {
                self.surface.reconfigure(&self.gpu.device);
                self.free_textures(&frees);
                self.window.request_redraw();
                return Ok(None);
            }
            wgpu::CurrentSurfaceTexture::Validation => {
                return Err(runtime("the window surface failed validation"))
            }
        };
        let target = frame.texture.create_view(&wgpu::TextureViewDescriptor {
            format: Some(self.surface.view_format),
            ..Default::default()
        });
        let stats = self.draw(&target, size, &primitives, &screen)?;
        let last_frame = opts.frames.is_some_and(|n| self.frames + 1 >= n);
        if let (true, Some(path)) = (last_frame, &opts.screenshot) {
            let capture = Capture::new(&self.gpu.device, self.surface.view_format, size.0, size.1)
                .map_err(|m| Failure::new(Exit::NotSupported, anyhow::anyhow!(m)))?;
            self.draw(&capture.view, size, &primitives, &screen)?;
            let pixels = capture.read(&self.gpu.device, &self.gpu.queue).map_err(runtime)?;
            write_png_rgba8(path, size.0, size.1, &pixels)
                .map_err(|e| Failure::new(Exit::Io, e))?;
        }
        self.window.pre_present_notify();
        self.gpu.queue.present(frame);
        self.free_textures(&frees);

        let at = Instant::now();
        self.frames += 1;
        let s = stats.unwrap_or_default();
        if stats.is_some() {
            self.last_stats = s;
        }
        self.meter.add(FrameSample {
            at_s: (at - self.started).as_secs_f64(),
            frame_ms: s.frame_ms,
            decode_ms: s.decode_ms,
            upload_ms: s.upload_ms,
            rebuild_ms: s.rebuild_ms,
            upload_bytes: s.upload_bytes,
            cache_bytes: s.cache_bytes,
            waited: s.decode_waits > 0,
        });
        if self.frames >= 2 {
            self.sum.0 += s.frame_ms;
            self.sum.1 += s.decode_ms;
            self.sum.2 += s.upload_ms;
            self.sum.3 += s.rebuild_ms;
        }
        if self.frames == 1 {
            self.second_frame_at = Some(at);
        }
        if last_frame {
            let n = self.frames;
            let timed = n.saturating_sub(1).max(1) as f64;
            let span = self.second_frame_at.map_or(0.0, |t| (at - t).as_secs_f64());
            return Ok(Some(RunReport {
                frames: n,
                seconds: (at - self.started).as_secs_f64(),
                fps: if n >= 2 && span > 0.0 { (n - 1) as f64 / span } else { 0.0 },
                frame_ms: self.sum.0 / timed,
                decode_ms: self.sum.1 / timed,
                upload_ms: self.sum.2 / timed,
                rebuild_ms: self.sum.3 / timed,
                frame_size: [size.0, size.1],
                msaa_samples: self.player.multisample_for(self.surface.view_format).samples,
                msaa_requested: self.player.options().msaa,
            }));
        }
        Ok(None)
    }

    /// The player's frame (or a black background under the gold standard) and the panels,
    /// into `target`. Returns the player's stats when it drew.
    fn draw(
        &mut self,
        target: &wgpu::TextureView,
        size: (u32, u32),
        primitives: &[egui::ClippedPrimitive],
        screen: &egui_wgpu::ScreenDescriptor,
    ) -> Result<Option<FrameStats>, Failure> {
        let gold = self.view.show_gold && self.gold_texture.is_some();
        let mut stats = None;
        if !gold {
            match self.player.render_to_view(
                &self.view.request(),
                target,
                self.surface.view_format,
                size,
            ) {
                Ok(s) => {
                    stats = Some(s);
                    self.message = None;
                }
                // A request the file cannot serve (a free camera the player refuses) is shown
                // in the panel; the window stays.
                Err(pis_play::PlayError::Request(m)) => self.message = Some(m),
                Err(e) => return Err(play_failure(e)),
            }
        }
        let device = &self.gpu.device;
        let mut encoder = device.create_command_encoder(&wgpu::CommandEncoderDescriptor {
            label: Some("pis-play panels"),
        });
        let user =
            self.renderer.update_buffers(device, &self.gpu.queue, &mut encoder, primitives, screen);
        {
            let load = if gold || stats.is_none() {
                wgpu::LoadOp::Clear(wgpu::Color::BLACK)
            } else {
                wgpu::LoadOp::Load
            };
            let pass = encoder.begin_render_pass(&wgpu::RenderPassDescriptor {
                label: Some("pis-play panels"),
                color_attachments: &[Some(wgpu::RenderPassColorAttachment {
                    view: target,
                    depth_slice: None,
                    resolve_target: None,
                    ops: wgpu::Operations { load, store: wgpu::StoreOp::Store },
                })],
                depth_stencil_attachment: None,
                timestamp_writes: None,
                occlusion_query_set: None,
                multiview_mask: None,
            });
            self.renderer.render(&mut pass.forget_lifetime(), primitives, screen);
        }
        self.gpu.queue.submit(user.into_iter().chain([encoder.finish()]));
        Ok(stats)
    }

    fn free_textures<'a>(&mut self, free: impl IntoIterator<Item = &'a egui::TextureId>) {
        for id in free {
            self.renderer.free_texture(id);
        }
    }

    /// Reads the gold-standard image nearest to the point when it is shown and changed.
    fn load_gold(&mut self) {
        if !self.view.show_gold {
            return;
        }
        let Some(set) = self.gold.as_mut() else { return };
        match set.image_near(&self.view.point) {
            Ok(img) => {
                if self.gold_texture.as_ref().is_none_or(|t| t.index != img.index) {
                    let color = egui::ColorImage::from_rgba_unmultiplied(
                        [img.width as usize, img.height as usize],
                        &img.srgba,
                    );
                    let texture = self.egui_ctx.load_texture(
                        "gold standard",
                        color,
                        egui::TextureOptions::LINEAR,
                    );
                    let label = format!(
                        "{} (point {})",
                        img.samples.iter().map(|s| s.to_string()).collect::<Vec<_>>().join(", "),
                        img.index
                    );
                    self.gold_texture = Some(GoldTexture {
                        index: img.index,
                        texture,
                        size: (img.width, img.height),
                        label,
                    });
                }
            }
            Err(m) => {
                self.message = Some(m);
                self.view.show_gold = false;
            }
        }
    }
}

/// The gold-standard image framed as the player frames the sample camera: the full image
/// height fills the window height (the camera's vertical field of view), centred across.
fn paint_gold(ui: &egui::Ui, id: egui::TextureId, w: u32, h: u32) {
    let rect = ui.max_rect();
    let scale = rect.height() / h.max(1) as f32;
    let fitted =
        egui::Rect::from_center_size(rect.center(), egui::vec2(w as f32 * scale, rect.height()));
    let uv = egui::Rect::from_min_max(egui::pos2(0.0, 0.0), egui::pos2(1.0, 1.0));
    ui.painter().image(id, fitted, uv, egui::Color32::WHITE);
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn default_window_is_a_whole_multiple_at_least_640_wide() {
        assert_eq!(default_window_size((40, 30)), (640, 480));
        assert_eq!(default_window_size((320, 240)), (640, 480));
        assert_eq!(default_window_size((300, 200)), (900, 600));
        assert_eq!(default_window_size((1280, 720)), (1280, 720));
    }
}
