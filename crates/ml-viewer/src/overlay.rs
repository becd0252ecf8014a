//! The egui overlay: the seed's "Material" and "Type" combos and the rest of the render
//! settings (`Choices`), pause, and a panel of per-pass GPU times with a frame-time graph.

use egui::{ComboBox, DragValue, Slider};
use ml_cpu::environment::{Environment, EnvironmentAsk, EnvironmentSource};
use ml_cpu::lights::{LightLayout, RadiusRange, SEED_RADIUS};
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene_request::{BuiltScene, SceneRequest, SceneSource};
use ml_render::settings::MAX_SHADOWED_LIGHTS;
use ml_render::{
    Antialiasing, Background, DebugView, Exposure, Geometry, LightGridMarks, OmniShadowMode, OmniShadowSettings, Raster, RenderSettings,
    ShadingModel, Technique,
};
use std::collections::VecDeque;

/// Everything the overlay can change that needs a new scene or renderer.
#[derive(Clone, Debug, PartialEq)]
pub struct Choices {
    /// The render settings chosen: technique, model, raster, samples, cluster grid, debug
    /// view, shadows, exposure, transparency (None: the scene has no transparent objects).
    /// Size, clock and the light grid's marks are the window's and the scene's (`settings`).
    pub settings: RenderSettings,
    /// Seed scene only: its object kind and material.
    pub object: MeshKind,
    pub material: Material,
    pub lights: u64,
    pub layout: LightLayout,
    pub radius: f32,
    /// Whether the light grid marks the cells near the surfaces (the command line's choice;
    /// auto decides again as lights and size change).
    pub light_grid_marks: LightGridMarks,
    /// The environment's intensity and turn in degrees (None: the scene has none).
    pub environment: Option<(f32, f32)>,
    /// An environment loaded in the viewer: a file, sky or none, as `--environment` reads it
    /// (None: the scene's own).
    pub environment_source: Option<String>,
}

impl Choices {
    /// What a viewer of `request`'s scene starts with: the scene as built, rendered with
    /// `settings` (the seed scene's object and material where the scene is another), the
    /// light grid's marks as asked (`settings` holds only what that choice resolved to at
    /// its first size).
    pub fn new(request: &SceneRequest, built: &BuiltScene, settings: &RenderSettings, light_grid_marks: LightGridMarks) -> Choices {
        let (object, material) = match request.source {
            SceneSource::Seed { object, material } => (object, material),
            _ => (MeshKind::Sphere, Material::built_in()[0]),
        };
        Choices {
            settings: RenderSettings { shading: built.shading, ..*settings },
            object,
            material,
            lights: built.scene.lights.len() as u64,
            layout: request.layout,
            radius: request.radius.map_or_else(|| built.scene.lights.first().map_or(SEED_RADIUS, |l| l.position_radius[3]), |r| r.max),
            environment: built.scene.sections.get::<Environment>().map(|e| (e.intensity, e.rotation.to_degrees())),
            environment_source: None,
            light_grid_marks,
        }
    }

    /// Light the scene with `source` (a file, sky or none) from the next renderer on, at the
    /// intensity and turn chosen so far (1 and 0° where there was none).
    pub fn load_environment(&mut self, source: &str) {
        self.environment_source = Some(source.to_owned());
        self.environment = match EnvironmentSource::parse(source) {
            EnvironmentSource::Off => None,
            _ => Some(self.environment.unwrap_or((1.0, 0.0))),
        };
    }

    /// `base` (the request these choices started from, as `initial`) with what changed since:
    /// the model, the seed scene's object and material, and the lights — a scene file keeps its
    /// own until their count, layout or radius changes.
    pub fn request(&self, base: &SceneRequest, initial: &Choices) -> SceneRequest {
        let mut r = SceneRequest { shading: Some(self.settings.shading), ..base.clone() };
        if let SceneSource::Seed { object, material } = &mut r.source {
            (*object, *material) = (self.object, self.material);
        }
        if self.environment_source.is_some() || self.environment.is_some() {
            let mut ask = r.sections.get::<EnvironmentAsk>().cloned().unwrap_or_default();
            if let Some(source) = &self.environment_source {
                ask.source = Some(EnvironmentSource::parse(source));
            }
            if let Some((intensity, degrees)) = self.environment {
                (ask.intensity, ask.rotation_deg) = (Some(intensity), Some(degrees));
            }
            r.sections.set(Some(ask));
        }
        if (self.lights, self.layout, self.radius) != (initial.lights, initial.layout, initial.radius) {
            (r.lights, r.layout) = (Some(self.lights), self.layout);
            if self.radius != initial.radius {
                r.radius = Some(RadiusRange::fixed(self.radius));
            }
        }
        r
    }

    /// The raster the technique draws with: the chosen one for visibility; the others have no
    /// visibility buffer to draw.
    fn drawn_raster(&self) -> Raster {
        if self.settings.technique.geometry() == Geometry::Meshlets {
            self.settings.raster
        } else {
            Raster::Hardware
        }
    }

    /// The settings of these choices at a size, the clock fixed at `time` if given.
    pub fn settings(&self, (width, height): (u32, u32), time: Option<f32>) -> RenderSettings {
        let s = &self.settings;
        // Transparent layers take samples in the visibility technique (the overlay offers
        // what the settings take).
        let antialiasing = if s.transparency.is_none() || ml_render::layers_take(s.technique, s.antialiasing) {
            s.antialiasing
        } else {
            Antialiasing::Off
        };
        RenderSettings {
            width,
            height,
            frames: 1,
            time,
            culling: true,
            raster: self.drawn_raster(),
            // The viewer's overlay shows times, not light counts.
            light_stats: false,
            light_grid_marks: self.light_grid_marks.resolve(self.lights, width, height, antialiasing),
            antialiasing,
            ..*s
        }
    }
}

/// Frames the graph shows.
const GRAPH_FRAMES: usize = 240;

/// The smallest window (points) the overlay opens in by itself.
const ROOMY: egui::Vec2 = egui::vec2(960.0, 540.0);

/// What the overlay shows besides the choices.
pub struct OverlayState {
    pub visible: bool,
    pub paused: bool,
    /// Wall time between frames, newest last (ms).
    pub frame_ms: VecDeque<f32>,
    /// The newest frame's GPU time per pass (ms).
    pub gpu: Vec<(&'static str, f64)>,
    /// Lights: the slider's value until it is let go (a new light count rebuilds the scene).
    pub lights_edit: u64,
    /// Whether the scene is the seed's (object and material apply).
    pub seed_scene: bool,
    /// The last settings error (shown until the next change).
    pub error: Option<String>,
    /// The EV the newest frame was exposed with (auto exposure moves it).
    pub exposure_ev: f32,
    /// Whether the window had room for the open panel when last drawn (None: not yet drawn).
    pub roomy: Option<bool>,
    /// The environment to load, as typed.
    pub environment_edit: String,
}

impl OverlayState {
    pub fn new(choices: &Choices, seed_scene: bool) -> OverlayState {
        OverlayState {
            visible: true,
            paused: false,
            frame_ms: VecDeque::new(),
            gpu: Vec::new(),
            lights_edit: choices.lights,
            seed_scene,
            error: None,
            exposure_ev: 0.0,
            roomy: None,
            environment_edit: String::new(),
        }
    }

    pub fn add_frame(&mut self, ms: f32) {
        if self.frame_ms.len() == GRAPH_FRAMES {
            self.frame_ms.pop_front();
        }
        self.frame_ms.push_back(ms);
    }
}

/// Draw the overlay; edits `choices` (the caller rebuilds when they differ from the current ones).
pub fn draw(ctx: &egui::Context, choices: &mut Choices, state: &mut OverlayState) {
    if !state.visible {
        return;
    }
    // The open panel is about 300×600 points: in a smaller window it starts folded to its
    // title bar (a click opens it), and it opens or folds again whenever the window crosses
    // ROOMY; in between it stays as the user left it, and scrolls where it is taller than
    // the window.
    let screen = ctx.content_rect().size();
    let roomy = screen.x >= ROOMY.x && screen.y >= ROOMY.y;
    let id = egui::Id::new("manylights overlay");
    if state.roomy != Some(roomy) {
        state.roomy = Some(roomy);
        let mut folding = egui::collapsing_header::CollapsingState::load_with_default_open(ctx, id.with("collapsing"), roomy);
        folding.set_open(roomy);
        folding.store(ctx);
    }
    let window = egui::Window::new("manylights").id(id).default_pos([8.0, 8.0]).resizable(false);
    window.vscroll(true).max_height((screen.y - 48.0).max(60.0)).show(ctx, |ui| {
        combo(ui, "Technique", &mut choices.settings.technique, &Technique::ALL, |t| t.name());
        if choices.settings.technique.geometry() == Geometry::Meshlets {
            let split = if choices.settings.raster.split() > 0 { choices.settings.raster.split() } else { Raster::DEFAULT_SPLIT };
            let options = [Raster::Hardware, Raster::hybrid(split), Raster::compute(split)];
            combo(ui, "Raster", &mut choices.settings.raster, &options, |r| r.name());
            if let Raster::Compute { split, .. } = &mut choices.settings.raster {
                ui.add(DragValue::new(split).range(1..=Raster::MAX_SPLIT).prefix("compute up to ").suffix(" px"));
            }
        }
        if choices.settings.transparency.is_none() || choices.settings.technique == Technique::Visibility {
            combo(ui, "Anti-aliasing", &mut choices.settings.antialiasing, &Antialiasing::ALL, |a| a.name());
        }
        ui.checkbox(&mut choices.settings.specular_aa, "Specular anti-aliasing");
        combo(ui, "Shading", &mut choices.settings.shading, &ShadingModel::ALL, |m| m.name());
        ui.add_enabled_ui(state.seed_scene, |ui| {
            combo(ui, "Type", &mut choices.object, &MeshKind::ALL, |k| k.name());
            combo(ui, "Material", &mut choices.material, &Material::built_in(), |m| m.name().unwrap_or("custom"));
        });
        let lights = ui.add(Slider::new(&mut state.lights_edit, 1..=1_000_000).logarithmic(true).text("lights"));
        if !lights.dragged() && !lights.has_focus() {
            choices.lights = state.lights_edit;
        }
        combo(ui, "Layout", &mut choices.layout, &LightLayout::ALL, |l| l.name());
        ui.add(Slider::new(&mut choices.radius, 0.1..=100.0).logarithmic(true).text("light radius"));
        if let Some((intensity, degrees)) = &mut choices.environment {
            ui.add(Slider::new(intensity, 0.0..=16.0).text("environment"));
            ui.add(Slider::new(degrees, -180.0..=180.0).suffix("°").text("turned"));
        }
        // Another environment (the pbr model's), loaded into a new renderer.
        if choices.settings.shading == ShadingModel::Pbr {
            ui.horizontal(|ui| {
                let field = egui::TextEdit::singleline(&mut state.environment_edit).hint_text("FILE.hdr|.exr, sky, none");
                ui.add(field.desired_width(150.0));
                if ui.button("Load").clicked() && !state.environment_edit.trim().is_empty() {
                    choices.load_environment(state.environment_edit.trim());
                }
            });
        }
        // The environment behind the scene where the model is lit by one.
        if choices.environment.is_some() && choices.settings.shading == ShadingModel::Pbr {
            combo(ui, "Background", &mut choices.settings.background, &Background::ALL, |b| b.name());
        } else {
            choices.settings.background = Background::Colour;
        }
        ui.horizontal(|ui| {
            let mut auto = choices.settings.exposure == Exposure::Auto;
            ui.checkbox(&mut auto, "auto");
            // Under auto the slider shows the EV the meter settled on; unticked, it starts there.
            let mut ev = match choices.settings.exposure {
                Exposure::Ev(ev) => ev,
                Exposure::Auto => state.exposure_ev,
            };
            ui.add_enabled(!auto, Slider::new(&mut ev, -8.0..=8.0).text("exposure (EV)"));
            choices.settings.exposure = if auto { Exposure::Auto } else { Exposure::Ev(ev) };
        });
        ui.horizontal(|ui| {
            ui.label("clusters");
            ui.add(DragValue::new(&mut choices.settings.clusters.x).range(1..=128));
            ui.add(DragValue::new(&mut choices.settings.clusters.y).range(1..=128));
            ui.add(DragValue::new(&mut choices.settings.clusters.z).range(1..=64));
        });
        combo(ui, "Debug view", &mut choices.settings.debug_view, &DebugView::all().collect::<Vec<_>>(), |v| v.name());
        let mut mode = choices.settings.omni.map(|o| o.mode);
        ComboBox::from_label("Point-light shadows").selected_text(mode.map_or("off", |m| m.name())).show_ui(ui, |ui| {
            ui.selectable_value(&mut mode, None, "off");
            for m in OmniShadowMode::ALL {
                ui.selectable_value(&mut mode, Some(m), m.name());
            }
        });
        let fresh = |mode| OmniShadowSettings { mode, lights: 1, all: false, size: OmniShadowSettings::DEFAULT_SIZE };
        // A mode keeps its own settings (the atlas its budget) when picked again.
        let same = |a: OmniShadowMode, b: OmniShadowMode| a.name() == b.name();
        choices.settings.omni = mode.map(|m| match choices.settings.omni {
            Some(o) if same(o.mode, m) => o,
            Some(o) => OmniShadowSettings { mode: m, ..o },
            None => fresh(m),
        });
        let scene_lights = u32::try_from(choices.lights).unwrap_or(u32::MAX).max(1);
        if let Some(o) = &mut choices.settings.omni {
            // The atlas takes thousands of lights; the cube array's memory grows by 6 faces a light.
            let max = if o.atlas().is_some() { MAX_SHADOWED_LIGHTS } else { 64 };
            ui.horizontal(|ui| {
                ui.add_enabled(!o.all, DragValue::new(&mut o.lights).range(1..=max).prefix("shadowed lights "));
                // As --shadowed-lights all: the lights that reach the view when it is ticked.
                ui.checkbox(&mut o.all, "all in view");
            });
            if o.all {
                o.lights = scene_lights.min(max);
            }
            match &mut o.mode {
                OmniShadowMode::Atlas(atlas) => {
                    ui.add(DragValue::new(&mut atlas.budget_mib).range(1..=16384).prefix("shadow budget MiB "));
                    ui.checkbox(&mut atlas.cache, "keep faces of still lights (cache)");
                }
                _ => {
                    ui.add(DragValue::new(&mut o.size).range(16..=4096).prefix("cube size "));
                }
            }
        }
        ui.checkbox(&mut state.paused, "pause (P)");
        if let Some(e) = &state.error {
            ui.colored_label(egui::Color32::LIGHT_RED, e);
        }
        ui.separator();
        for (pass, ms) in &state.gpu {
            ui.label(format!("{pass}: {ms:.3} ms"));
        }
        frame_graph(ui, &state.frame_ms);
    });
}

fn combo<T: Clone + PartialEq>(ui: &mut egui::Ui, label: &str, value: &mut T, options: &[T], name: impl Fn(&T) -> &str) {
    ComboBox::from_label(label).selected_text(name(value).to_owned()).show_ui(ui, |ui| {
        for o in options {
            ui.selectable_value(value, o.clone(), name(o));
        }
    });
}

/// Frame times as a polyline, 0 at the bottom, the window's largest at the top.
fn frame_graph(ui: &mut egui::Ui, ms: &VecDeque<f32>) {
    let top = ms.iter().copied().fold(1.0f32, f32::max);
    let newest = ms.back().copied().unwrap_or(0.0);
    ui.label(format!("frame {newest:.1} ms (graph top {top:.1} ms)"));
    let (rect, _) = ui.allocate_exact_size(egui::vec2(240.0, 60.0), egui::Sense::hover());
    let painter = ui.painter_at(rect);
    painter.rect_filled(rect, 0.0, egui::Color32::from_black_alpha(120));
    let points: Vec<egui::Pos2> = ms
        .iter()
        .enumerate()
        .map(|(i, &m)| egui::pos2(rect.left() + rect.width() * i as f32 / GRAPH_FRAMES as f32, rect.bottom() - rect.height() * m / top))
        .collect();
    painter.add(egui::Shape::line(points, egui::Stroke::new(1.0, egui::Color32::LIGHT_GREEN)));
}

#[cfg(test)]
mod tests {
    use super::*;

    fn initial() -> Choices {
        Choices {
            settings: RenderSettings::new(Technique::Forward, 64, 64),
            object: MeshKind::Sphere,
            material: Material::built_in()[0],
            lights: 7,
            layout: LightLayout::Grid,
            radius: 3.0,
            light_grid_marks: LightGridMarks::Auto,
            environment: None,
            environment_source: None,
        }
    }

    #[test]
    fn only_the_visibility_technique_takes_the_compute_raster() {
        let start = initial();
        let compute = Choices { settings: RenderSettings { raster: Raster::compute(16), ..start.settings }, ..start };
        assert_eq!(compute.settings((64, 64), None).raster, Raster::Hardware);
        let visibility = Choices { settings: RenderSettings { technique: Technique::Visibility, ..compute.settings }, ..compute };
        assert_eq!(visibility.settings((64, 64), None).raster, Raster::compute(16));
    }

    #[test]
    fn a_file_keeps_its_lights_until_their_count_layout_or_radius_changes() {
        let base =
            SceneRequest { radius: Some(RadiusRange { min: 1.0, max: 3.0 }), ..SceneRequest::new(SceneSource::File("a.toml".into())) };
        let start = initial();
        let pbr = Choices { settings: RenderSettings { shading: ShadingModel::Pbr, ..start.settings }, ..start.clone() };
        assert_eq!(pbr.request(&base, &start), SceneRequest { shading: Some(ShadingModel::Pbr), ..base.clone() });
        let more = Choices { lights: 9, layout: LightLayout::Random, ..start.clone() }.request(&base, &start);
        assert_eq!((more.lights, more.layout, more.radius), (Some(9), LightLayout::Random, base.radius));
        let smaller = Choices { radius: 2.0, ..start.clone() }.request(&base, &start);
        assert_eq!((smaller.lights, smaller.radius), (Some(7), Some(RadiusRange::fixed(2.0))));
    }

    #[test]
    fn the_seed_scene_takes_the_object_and_material_chosen() {
        let start = initial();
        let base = SceneRequest::new(SceneSource::Seed { object: start.object, material: start.material });
        let copper = Material::named("copper").unwrap();
        let teapot = Choices { object: MeshKind::Teapot, material: copper, ..start.clone() }.request(&base, &start);
        assert_eq!(teapot.source, SceneSource::Seed { object: MeshKind::Teapot, material: copper });
        assert_eq!(teapot.lights, None);
    }

    /// What `r` asks of the environment (nothing: the default ask).
    fn ask(r: &SceneRequest) -> EnvironmentAsk {
        r.sections.get::<EnvironmentAsk>().cloned().unwrap_or_default()
    }

    #[test]
    fn an_environments_intensity_and_turn_go_into_the_request() {
        let base = SceneRequest::new(SceneSource::File("a.glb".into()));
        let start = Choices { environment: Some((1.0, 0.0)), ..initial() };
        let turned = Choices { environment: Some((2.0, 90.0)), ..start.clone() }.request(&base, &start);
        assert_eq!((ask(&turned).intensity, ask(&turned).rotation_deg), (Some(2.0), Some(90.0)));
        let none = initial().request(&base, &initial());
        assert_eq!((ask(&none).intensity, ask(&none).rotation_deg), (None, None));
    }

    #[test]
    fn an_environment_loaded_goes_into_the_request_at_the_intensity_chosen() {
        let base = SceneRequest::new(SceneSource::File("a.glb".into()));
        let mut lit = Choices { environment: Some((2.0, 90.0)), ..initial() };
        lit.load_environment("studio.hdr");
        let r = lit.request(&base, &initial());
        assert_eq!(ask(&r).source, Some(EnvironmentSource::File("studio.hdr".into())));
        assert_eq!((ask(&r).intensity, ask(&r).rotation_deg), (Some(2.0), Some(90.0)));
        // A scene without one starts at 1 and 0°; none takes the sliders away.
        let mut dark = initial();
        dark.load_environment("sky");
        assert_eq!((dark.environment, ask(&dark.request(&base, &initial())).source), (Some((1.0, 0.0)), Some(EnvironmentSource::Sky)));
        dark.load_environment("none");
        assert_eq!((dark.environment, ask(&dark.request(&base, &initial())).source), (None, Some(EnvironmentSource::Off)));
    }
}
