//! The egui overlay: the seed's "Material" and "Type" combos and the rest of the render
//! settings (`Choices`), pause, and a panel of per-pass GPU times with a frame-time graph.

use egui::{ComboBox, DragValue, Slider};
use ml_cpu::cluster::ClusterDims;
use ml_cpu::material::NAMED_ALBEDOS;
use ml_cpu::mesh::MeshKind;
use ml_render::{DebugView, OmniShadowMode, OmniShadowSettings, ShadingModel, Technique};
use std::collections::VecDeque;

/// Everything the overlay can change that needs a new scene or renderer.
#[derive(Clone, Debug, PartialEq)]
pub struct Choices {
    pub technique: Technique,
    pub shading: ShadingModel,
    /// Seed scene only: its object kind and material.
    pub object: String,
    pub material: String,
    pub lights: u64,
    /// "grid" or "random".
    pub layout: String,
    pub radius: f32,
    pub clusters: ClusterDims,
    pub debug_view: DebugView,
    pub omni: Option<OmniShadowSettings>,
}

/// Frames the graph shows.
const GRAPH_FRAMES: usize = 240;

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
    egui::Window::new("manylights").default_pos([8.0, 8.0]).resizable(false).show(ctx, |ui| {
        combo(ui, "Technique", &mut choices.technique, &Technique::ALL, |t| t.name());
        combo(ui, "Shading", &mut choices.shading, &ShadingModel::ALL, |m| m.name());
        ui.add_enabled_ui(state.seed_scene, |ui| {
            let kinds: Vec<String> = MeshKind::ALL.iter().map(|k| k.name().to_owned()).collect();
            combo(ui, "Type", &mut choices.object, &kinds, |k| k.as_str());
            let materials: Vec<String> = NAMED_ALBEDOS.iter().map(|(n, _)| (*n).to_owned()).collect();
            combo(ui, "Material", &mut choices.material, &materials, |m| m.as_str());
        });
        let lights = ui.add(Slider::new(&mut state.lights_edit, 1..=1_000_000).logarithmic(true).text("lights"));
        if !lights.dragged() && !lights.has_focus() {
            choices.lights = state.lights_edit;
        }
        let layouts = ["grid".to_owned(), "random".to_owned()];
        combo(ui, "Layout", &mut choices.layout, &layouts, |l| l.as_str());
        ui.add(Slider::new(&mut choices.radius, 0.1..=100.0).logarithmic(true).text("light radius"));
        ui.horizontal(|ui| {
            ui.label("clusters");
            ui.add(DragValue::new(&mut choices.clusters.x).range(1..=128));
            ui.add(DragValue::new(&mut choices.clusters.y).range(1..=128));
            ui.add(DragValue::new(&mut choices.clusters.z).range(1..=64));
        });
        combo(ui, "Debug view", &mut choices.debug_view, &DebugView::ALL, |v| v.name());
        let mut mode = choices.omni.map(|o| o.mode);
        ComboBox::from_label("Point-light shadows").selected_text(mode.map_or("off", |m| m.name())).show_ui(ui, |ui| {
            ui.selectable_value(&mut mode, None, "off");
            for m in OmniShadowMode::ALL {
                ui.selectable_value(&mut mode, Some(m), m.name());
            }
        });
        let fresh = |mode| OmniShadowSettings { mode, lights: 1, size: OmniShadowSettings::DEFAULT_SIZE };
        choices.omni = mode.map(|m| choices.omni.map_or(fresh(m), |o| OmniShadowSettings { mode: m, ..o }));
        if let Some(o) = &mut choices.omni {
            ui.add(DragValue::new(&mut o.lights).range(1..=64).prefix("shadowed lights "));
            ui.add(DragValue::new(&mut o.size).range(16..=4096).prefix("cube size "));
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
