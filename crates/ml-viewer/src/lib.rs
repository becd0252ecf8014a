//! `manylights view` (docs/usage.md#view-the-window): a window on the renderer. Each frame is
//! the headless renderer's frame (same passes, same frames in flight) with a present hook: the
//! colour target is blitted into the swapchain image and the egui overlay drawn over it
//! (present.rs). winit's events are pumped from this loop (no callback owns the renderer), so
//! context, renderer and window live on one stack and drop in order.

pub mod camera_control;
pub mod overlay;
pub mod present;
pub mod script;

use anyhow::{bail, Context as _, Result};
use camera_control::FirstPerson;
use ml_cpu::scene::Scene;
use ml_cpu::scene_request::SceneRequest;
use ml_render::report::FrameStats;
use ml_render::{EnvironmentView, RenderSettings, Renderer, TIMER_SPEED};
use ml_vk::swapchain::Acquired;
use ml_vk::{vk, Context, ContextDesc, WindowHandles};
pub use overlay::Choices;
use overlay::OverlayState;
use present::{PresentFrame, Presenter};
use raw_window_handle::{HasDisplayHandle, HasWindowHandle};
use script::Command;
use std::collections::VecDeque;
use std::path::Path;
use std::sync::atomic::Ordering;
use std::time::{Duration, Instant};
use winit::application::ApplicationHandler;
use winit::event::{ElementState, MouseButton, MouseScrollDelta, WindowEvent};
use winit::event_loop::{ActiveEventLoop, EventLoop};
use winit::keyboard::{KeyCode, PhysicalKey};
use winit::platform::pump_events::{EventLoopExtPumpEvents, PumpStatus};
use winit::window::{Window, WindowId};

/// How the viewer starts.
pub struct ViewerOptions {
    /// The scene; the overlay's changes are made to it (`Choices::request`).
    pub scene: SceneRequest,
    /// The choices it starts with (`Choices::new`).
    pub choices: Choices,
    /// Window (and first render) size.
    pub width: u32,
    pub height: u32,
    /// FIFO presentation; false: mailbox or immediate where the surface has them.
    pub vsync: bool,
    pub validation: bool,
    pub device: Option<usize>,
    /// A fixed animation clock (scripted sessions); None: real time.
    pub time: Option<f32>,
    pub script: Option<Vec<Command>>,
}

/// Makes the scene and settings for a set of choices at a size.
type Build<'a> = dyn Fn(&Choices, (u32, u32)) -> Result<(Scene, RenderSettings)> + 'a;

/// The connection to the window system the viewer's window opens on. Made before any GPU
/// work (`auto`'s probes), so that a machine without a display says so at once.
pub struct WindowSystem(EventLoop<()>);

/// Connect to the window system (one error line where there is none).
pub fn connect() -> Result<WindowSystem> {
    EventLoop::new().context("cannot open a window (no display? set DISPLAY, or run under xvfb-run)").map(WindowSystem)
}

/// Open the window on `windows` and run until it is closed, Esc is pressed or the script quits.
pub fn run(windows: WindowSystem, options: ViewerOptions) -> Result<()> {
    // What the request builds is what `render` would show. A rebuilt scene's warnings are
    // dropped: its file gave them when the viewer started.
    let (initial, base, time) = (options.choices.clone(), options.scene.clone(), options.time);
    let build = move |c: &Choices, size: (u32, u32)| -> Result<(Scene, RenderSettings)> {
        let built = c.request(&base, &initial).build()?;
        Ok((built.scene, c.settings(size, time)))
    };
    run_with(windows, options, &build)
}

fn run_with(WindowSystem(mut event_loop): WindowSystem, options: ViewerOptions, build: &Build) -> Result<()> {
    let mut events = Events { size: (options.width, options.height), ..Events::default() };
    while events.window.is_none() {
        if let PumpStatus::Exit(_) = event_loop.pump_app_events(Some(Duration::from_millis(10)), &mut events) {
            bail!("the window system closed the event loop before the window opened");
        }
        if let Some(e) = events.error.take() {
            bail!(e);
        }
    }
    let window = events.window.as_ref().expect("made above");
    let handles = WindowHandles {
        display: window.display_handle().context("the window's display")?.as_raw(),
        window: window.window_handle().context("the window's handle")?.as_raw(),
    };
    let ctx = Context::new(&ContextDesc { validation: options.validation, device_index: options.device, window: Some(handles) })?;
    let messages = ctx.validation_counter();
    let result = Session::run(&ctx, &mut event_loop, &mut events, options, build);
    // Context (and its surface) before the window.
    drop(ctx);
    events.window = None;
    result?;
    let count = messages.load(Ordering::SeqCst);
    if count > 0 {
        bail!("{count} validation message(s) (printed above)");
    }
    Ok(())
}

/// winit's side: the window, and the events since the last frame.
#[derive(Default)]
struct Events {
    size: (u32, u32),
    window: Option<Window>,
    queue: Vec<WindowEvent>,
    error: Option<String>,
}

impl ApplicationHandler for Events {
    fn resumed(&mut self, event_loop: &ActiveEventLoop) {
        if self.window.is_none() {
            let attributes = Window::default_attributes()
                .with_title("manylights")
                .with_inner_size(winit::dpi::PhysicalSize::new(self.size.0, self.size.1));
            match event_loop.create_window(attributes) {
                Ok(w) => self.window = Some(w),
                Err(e) => self.error = Some(format!("cannot open a window: {e}")),
            }
        }
    }

    fn window_event(&mut self, _: &ActiveEventLoop, _: WindowId, event: WindowEvent) {
        self.queue.push(event);
    }
}

/// The viewer's state between frames.
struct Session<'c> {
    ctx: &'c Context,
    renderer: Option<Renderer<'c>>,
    presenter: Presenter,
    /// What the overlay shows (and the user edits), and what the renderer was made with.
    choices: Choices,
    built: Option<Choices>,
    overlay: OverlayState,
    egui: egui::Context,
    egui_winit: egui_winit::State,
    command_pool: vk::CommandPool,
    control: FirstPerson,
    /// Right mouse button held: mouse motion turns the camera (the last cursor position).
    looking: Option<(f64, f64)>,
    /// Mouse motion while looking since the last frame (pixels).
    drag: (f64, f64),
    clock: f32,
    fixed_time: Option<f32>,
    vsync: bool,
    minimized: bool,
    swapchain_stale: bool,
    script: VecDeque<Command>,
    /// Script: loop turns to let pass before the next command.
    wait_turns: u32,
    screenshot: Option<std::path::PathBuf>,
    window_shot: Option<std::path::PathBuf>,
    quit: bool,
    counts: Counts,
    /// Lights drawn as markers (`--show-lights`): objects that follow the lights.
    show_lights: bool,
}

/// What a session did (printed at the end of a scripted one).
#[derive(Default, Debug)]
struct Counts {
    frames: u32,
    swapchains: u32,
    resizes: u32,
    /// Overlay changes made in place (new lights, objects, grid or debug view; same pipelines).
    changes_in_place: u32,
    renderers: u32,
    /// Loop turns without a frame: the window was minimised or had no area.
    paused_turns: u32,
}

impl<'c> Session<'c> {
    fn run(ctx: &'c Context, event_loop: &mut EventLoop<()>, events: &mut Events, options: ViewerOptions, build: &Build) -> Result<()> {
        let window = events.window.as_ref().expect("the window is open");
        let size = window.inner_size();
        let extent = vk::Extent2D { width: size.width.max(1), height: size.height.max(1) };
        let mut presenter = Presenter::new(ctx, extent, options.vsync, ml_render::FRAMES_IN_FLIGHT)?;
        let pool_info = vk::CommandPoolCreateInfo::default().queue_family_index(ctx.queue_family);
        // SAFETY: valid device and create info.
        let command_pool = match unsafe { ctx.device.create_command_pool(&pool_info, None) } {
            Ok(p) => p,
            Err(e) => {
                presenter.destroy(ctx);
                bail!("vkCreateCommandPool: {e}");
            }
        };
        let egui = egui::Context::default();
        let egui_winit =
            egui_winit::State::new(egui.clone(), egui::ViewportId::ROOT, window, Some(window.scale_factor() as f32), None, None);
        let mut session = Session {
            ctx,
            renderer: None,
            overlay: OverlayState::new(&options.choices, options.scene.is_seed()),
            show_lights: options.scene.show_lights,
            choices: options.choices,
            built: None,
            presenter,
            egui,
            egui_winit,
            command_pool,
            control: FirstPerson::default(),
            looking: None,
            drag: (0.0, 0.0),
            clock: options.time.unwrap_or(0.0),
            fixed_time: options.time,
            vsync: options.vsync,
            minimized: false,
            swapchain_stale: false,
            script: options.script.unwrap_or_default().into(),
            wait_turns: 0,
            screenshot: None,
            window_shot: None,
            quit: false,
            counts: Counts { swapchains: 1, ..Counts::default() },
        };
        let scripted = !session.script.is_empty();
        let result = session.main_loop(event_loop, events, build);
        session.release();
        if scripted && result.is_ok() {
            let c = &session.counts;
            println!(
                "view: {} frames, {} swapchains, {} renderer resizes, {} changes in place, {} renderers, {} turns paused",
                c.frames, c.swapchains, c.resizes, c.changes_in_place, c.renderers, c.paused_turns
            );
        }
        result
    }

    fn release(&mut self) {
        let _ = self.ctx.wait_idle();
        self.renderer = None;
        self.presenter.destroy(self.ctx);
        // SAFETY: idle device; the pool's buffers (egui's uploads) are done.
        unsafe { self.ctx.device.destroy_command_pool(self.command_pool, None) };
    }

    fn main_loop(&mut self, event_loop: &mut EventLoop<()>, events: &mut Events, build: &Build) -> Result<()> {
        let mut last = Instant::now();
        let mut camera = None;
        let first = self.presenter.swapchain.extent;
        let mut made_for = (first.width, first.height);
        loop {
            let timeout = if self.minimized { Duration::from_millis(16) } else { Duration::ZERO };
            if let PumpStatus::Exit(_) = event_loop.pump_app_events(Some(timeout), events) {
                return Ok(());
            }
            let window = events.window.as_ref().expect("open until the session ends");
            for event in std::mem::take(&mut events.queue) {
                self.handle(window, &event);
            }
            self.run_script(window)?;
            if self.quit {
                return Ok(());
            }
            let now = Instant::now();
            let seconds = now.duration_since(last).as_secs_f32();
            last = now;
            let size = window.inner_size();
            if self.minimized || size.width == 0 || size.height == 0 {
                self.counts.paused_turns += 1;
                continue;
            }
            // The size the swapchain was last made for (the surface may settle on another).
            if self.swapchain_stale || made_for != (size.width, size.height) {
                self.ctx.wait_idle()?;
                self.presenter.recreate(self.ctx, vk::Extent2D { width: size.width, height: size.height }, self.vsync)?;
                self.swapchain_stale = false;
                self.counts.swapchains += 1;
                made_for = (size.width, size.height);
            }
            let extent = self.presenter.swapchain.extent;
            // A renderer for the current choices at the window's size.
            let fits = self.renderer.as_ref().is_some_and(|r| {
                let s = r.settings();
                (s.width, s.height) == (extent.width, extent.height)
            });
            let changed = self.choices_changed();
            if let (Some(r), false) = (&mut self.renderer, fits) {
                // A new size needs new targets, not new pipelines.
                r.reconfigure(RenderSettings { width: extent.width, height: extent.height, ..*r.settings() })?;
                self.counts.resizes += 1;
            }
            if changed && !self.change_in_place(build, extent) {
                camera = self.renderer.as_ref().map(|r| r.camera()).or(camera);
                self.rebuild(build, extent, camera)?;
            }
            let renderer = self.renderer.as_mut().expect("made above");
            if self.drag != (0.0, 0.0) {
                renderer.set_camera(self.control.turned(renderer.camera(), std::mem::take(&mut self.drag)))?;
            }
            if self.control.keys != camera_control::MoveKeys::default() {
                renderer.set_camera(self.control.moved(renderer.camera(), seconds))?;
            }
            if !self.overlay.paused && self.fixed_time.is_none() {
                self.clock += seconds * TIMER_SPEED;
            }
            self.overlay.add_frame(seconds * 1e3);
            self.frame(window)?;
        }
    }

    /// Whether the overlay changed a setting the renderer was made with.
    fn choices_changed(&self) -> bool {
        self.built.as_ref() != Some(&self.choices)
    }

    /// Apply the changed choices to the current renderer where they allow it: new lights
    /// (count, layout, radius), objects (kind, material), the environment's intensity and turn,
    /// cluster grid, debug view or exposure. False if
    /// they do not (or it failed): a new renderer then.
    fn change_in_place(&mut self, build: &Build, extent: vk::Extent2D) -> bool {
        let (Some(renderer), Some(built)) = (&mut self.renderer, &self.built) else { return false };
        let (c, b) = (&self.choices, &built.settings);
        let lights_only = Choices { lights: built.lights, layout: built.layout, radius: built.radius, ..c.clone() } == *built;
        let settings_only = Choices {
            settings: RenderSettings { clusters: b.clusters, debug_view: b.debug_view, exposure: b.exposure, ..c.settings },
            ..c.clone()
        } == *built;
        let objects_only = Choices { object: built.object, material: built.material, ..c.clone() } == *built;
        let environment_only = Choices { environment: built.environment, ..c.clone() } == *built;
        let done = if environment_only {
            let (intensity, degrees) = c.environment.unwrap_or((1.0, 0.0));
            matches!(renderer.set_environment_view(intensity, degrees.to_radians()), Ok(true))
        } else if lights_only {
            // With markers shown the objects change with the lights: their markers too.
            let markers = self.show_lights;
            let changed = build(c, (extent.width, extent.height)).and_then(|(scene, _)| {
                renderer.set_lights(scene.lights.clone())?;
                Ok(!markers || renderer.set_objects(&scene)?)
            });
            matches!(changed, Ok(true))
        } else if objects_only {
            matches!(build(c, (extent.width, extent.height)).and_then(|(scene, _)| Ok(renderer.set_objects(&scene)?)), Ok(true))
        } else if settings_only {
            let settings = RenderSettings {
                clusters: c.settings.clusters,
                debug_view: c.settings.debug_view,
                exposure: c.settings.exposure,
                ..*renderer.settings()
            };
            matches!(renderer.reconfigure(settings), Ok(true))
        } else {
            false
        };
        if done {
            self.built = Some(self.choices.clone());
            self.counts.changes_in_place += 1;
        }
        done
    }

    /// A renderer for the current choices at `extent`, seen from `camera` if given (the
    /// scene's own camera otherwise). A new scene, pipelines and targets: what a changed
    /// technique, model, light count or size needs. If the choices cannot be rendered, the
    /// previous ones come back and the overlay says why.
    fn rebuild(&mut self, build: &Build, extent: vk::Extent2D, camera: Option<ml_cpu::camera::Camera>) -> Result<()> {
        self.ctx.wait_idle()?;
        self.renderer = None;
        let made = build(&self.choices, (extent.width, extent.height)).and_then(|(scene, settings)| {
            let mut r = Renderer::new(self.ctx, scene, settings)?;
            if let Some(c) = camera {
                r.set_camera(c)?;
            }
            // Auto exposure starts where it settles, not dark.
            r.settle_first_exposure(self.clock)?;
            Ok(r)
        });
        match (made, self.built.clone()) {
            (Ok(r), _) => {
                self.renderer = Some(r);
                self.counts.renderers += 1;
                self.built = Some(self.choices.clone());
                self.overlay.error = None;
                Ok(())
            }
            (Err(e), Some(previous)) if previous != self.choices => {
                self.overlay.error = Some(format!("{e:#}"));
                self.choices = previous;
                self.overlay.lights_edit = self.choices.lights;
                self.built = None;
                self.rebuild(build, extent, camera)
            }
            (Err(e), _) => Err(e),
        }
    }

    /// Input: egui first; what it does not take moves the camera or is a shortcut.
    fn handle(&mut self, window: &Window, event: &WindowEvent) {
        let taken = self.egui_winit.on_window_event(window, event).consumed;
        match event {
            WindowEvent::CloseRequested => self.quit = true,
            WindowEvent::Resized(size) => {
                self.minimized = size.width == 0 || size.height == 0;
                let current = self.presenter.swapchain.extent;
                self.swapchain_stale |= (size.width, size.height) != (current.width, current.height);
            }
            WindowEvent::Occluded(hidden) => self.minimized = *hidden,
            WindowEvent::KeyboardInput { event: key, .. } if !taken => {
                let down = key.state == ElementState::Pressed;
                let keys = &mut self.control.keys;
                match key.physical_key {
                    PhysicalKey::Code(KeyCode::KeyW) => keys.forward = down,
                    PhysicalKey::Code(KeyCode::KeyS) => keys.back = down,
                    PhysicalKey::Code(KeyCode::KeyA) => keys.left = down,
                    PhysicalKey::Code(KeyCode::KeyD) => keys.right = down,
                    PhysicalKey::Code(KeyCode::KeyQ) => keys.down = down,
                    PhysicalKey::Code(KeyCode::KeyE) => keys.up = down,
                    PhysicalKey::Code(KeyCode::KeyP) if down && !key.repeat => self.overlay.paused = !self.overlay.paused,
                    PhysicalKey::Code(KeyCode::F12) if down && !key.repeat => {
                        self.screenshot = Some(std::path::PathBuf::from(format!("manylights-{}.png", timestamp())));
                    }
                    PhysicalKey::Code(KeyCode::KeyC) if down && !key.repeat => {
                        if let Some(camera) = self.renderer.as_ref().map(|r| r.camera()) {
                            // The target only gives the direction: a tenth of the way to the far plane.
                            println!("--camera {}", ml_cpu::camera::CameraSpec::describe(&camera, camera.far * 0.1));
                        }
                    }
                    PhysicalKey::Code(KeyCode::KeyF) if down && !key.repeat => {
                        // Frame the scene for the window as it is now (a file's first view).
                        if let Some(r) = self.renderer.as_mut() {
                            let aspect = r.settings().width as f32 / r.settings().height.max(1) as f32;
                            let framed = ml_cpu::framing::frame_scene(r.scene(), aspect, r.camera().fov_y_deg);
                            if let Err(e) = r.set_camera(framed) {
                                self.overlay.error = Some(format!("{e:#}"));
                            }
                        }
                    }
                    PhysicalKey::Code(KeyCode::Escape) if down => self.quit = true,
                    _ => {}
                }
            }
            WindowEvent::MouseInput { state, button: MouseButton::Right, .. } if !taken || *state == ElementState::Released => {
                self.looking = (*state == ElementState::Pressed).then_some((f64::NAN, f64::NAN));
            }
            WindowEvent::CursorMoved { position, .. } => {
                if let Some((x, y)) = self.looking {
                    if !x.is_nan() {
                        self.drag.0 += position.x - x;
                        self.drag.1 += position.y - y;
                    }
                    self.looking = Some((position.x, position.y));
                }
            }
            WindowEvent::MouseWheel { delta, .. } if !taken => {
                let lines = match delta {
                    MouseScrollDelta::LineDelta(_, y) => *y,
                    MouseScrollDelta::PixelDelta(p) => p.y as f32 / 40.0,
                };
                self.control.scroll(lines);
            }
            _ => {}
        }
    }

    /// Run script commands until one has to wait for frames.
    fn run_script(&mut self, window: &Window) -> Result<()> {
        if self.wait_turns > 0 {
            self.wait_turns -= 1;
            return Ok(());
        }
        while let Some(command) = self.script.pop_front() {
            match command {
                Command::Frames(n) => {
                    self.wait_turns = n;
                    return Ok(());
                }
                Command::Technique(name) => self.choices.settings.technique = ml_render::Technique::from_name(&name)?,
                Command::Antialiasing(samples) => self.choices.settings.antialiasing = ml_render::Antialiasing::from_name(&samples)?,
                Command::Environment(source) => self.choices.load_environment(&source),
                Command::Background(shown) => self.choices.settings.background = ml_render::Background::from_name(&shown)?,
                Command::Lights(n) => {
                    self.choices.lights = n;
                    self.overlay.lights_edit = n;
                }
                Command::Resize(w, h) => {
                    // The window system may answer later, or with another size: the swapchain
                    // follows whatever the window reports.
                    let _ = window.request_inner_size(winit::dpi::PhysicalSize::new(w, h));
                }
                Command::Minimize => window.set_minimized(true),
                Command::Restore => {
                    window.set_minimized(false);
                    window.focus_window();
                }
                Command::Overlay(on) => self.overlay.visible = on,
                Command::Screenshot(path) => self.screenshot = Some(path),
                Command::WindowShot(path) => self.window_shot = Some(path),
                Command::Quit => self.quit = true,
            }
            if self.screenshot.is_some() || self.window_shot.is_some() {
                // Taken from the next frame drawn.
                return Ok(());
            }
        }
        Ok(())
    }

    /// Draw and present one frame (and take the screenshots asked for).
    fn frame(&mut self, window: &Window) -> Result<()> {
        let renderer = self.renderer.as_mut().expect("made before a frame");
        let mut stats = FrameStats::new(&renderer.timed_passes());
        let slot = renderer.wait_next_slot(&mut stats)?;
        let image = match self.presenter.swapchain.acquire(self.presenter.acquire_semaphore(slot))? {
            Acquired::Image { index, suboptimal } => {
                self.swapchain_stale |= suboptimal;
                index
            }
            Acquired::OutOfDate => {
                self.swapchain_stale = true;
                return Ok(());
            }
        };
        let input = self.egui_winit.take_egui_input(window);
        let (choices, overlay) = (&mut self.choices, &mut self.overlay);
        let output = self.egui.run(input, |ctx| overlay::draw(ctx, choices, overlay));
        self.egui_winit.handle_platform_output(window, output.platform_output);
        let primitives = if self.overlay.visible { self.egui.tessellate(output.shapes, output.pixels_per_point) } else { Vec::new() };
        let egui_renderer = self.presenter.egui.as_mut().expect("made with the presenter");
        egui_renderer
            .set_textures(self.ctx.queue, self.command_pool, output.textures_delta.set.as_slice())
            .map_err(|e| anyhow::anyhow!("the overlay's textures: {e}"))?;
        let capture = self.window_shot.is_some();
        let mut hook = PresentFrame {
            presenter: &mut self.presenter,
            image,
            slot,
            primitives: &primitives,
            pixels_per_point: output.pixels_per_point,
            capture,
        };
        let t = self.clock;
        renderer.draw(t, &mut hook, &mut stats)?;
        self.counts.frames += 1;
        if !self.presenter.swapchain.present(self.ctx, image, self.presenter.rendered_semaphore(image))? {
            self.swapchain_stale = true;
        }
        if !output.textures_delta.free.is_empty() {
            self.ctx.wait_idle()?;
            egui_renderer_free(&mut self.presenter, &output.textures_delta.free)?;
        }
        let renderer = self.renderer.as_mut().expect("made before a frame");
        self.overlay.gpu = stats.gpu_ms().unwrap_or_default();
        self.overlay.exposure_ev = renderer.exposure_ev();
        if let Some(path) = self.screenshot.take() {
            let rgba = renderer.read_newest()?;
            let s = renderer.settings();
            save_png(&path, s.width, s.height, &rgba)?;
        }
        if let Some(path) = self.window_shot.take() {
            self.ctx.wait_idle()?;
            let (w, h, rgba) = self.presenter.captured_rgba().context("no window-shot was taken")?;
            save_png(&path, w, h, &rgba)?;
        }
        Ok(())
    }
}

fn egui_renderer_free(presenter: &mut Presenter, ids: &[egui::TextureId]) -> Result<()> {
    let renderer = presenter.egui.as_mut().expect("made with the presenter");
    renderer.free_textures(ids).map_err(|e| anyhow::anyhow!("the overlay's textures: {e}"))
}

/// A screenshot replaces a file of its name only once complete.
fn save_png(path: &Path, width: u32, height: u32, rgba: &[u8]) -> Result<()> {
    Ok(ml_cpu::files::write_png(path, rgba, (width, height))?)
}

/// Seconds since the Unix epoch (screenshot names).
fn timestamp() -> u64 {
    std::time::SystemTime::now().duration_since(std::time::UNIX_EPOCH).map_or(0, |d| d.as_secs())
}
