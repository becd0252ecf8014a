//! A scene as a command asks for it — which scene, how many lights and how they are placed,
//! which shading model — and the building of it. What is left out or worth knowing comes back
//! as warnings, for the caller to show.

use crate::bench_scene::bench_scene;
use crate::camera::CameraSpec;
use crate::framing::{frame_scene, DEFAULT_ASPECT};
use crate::gltf_scene::{self, GltfFileError};
use crate::lights::{LightColors, LightFrame, LightLayout, LightParams, RadiusRange, DEFAULT_RIG_LIGHTS, SEED_LIGHT_COUNT, SEED_RADIUS};
use crate::material::Material;
use crate::mesh::MeshKind;
use crate::scene::Scene;
use crate::scene_file::{self, SceneFileError};
use crate::scene_section::{Section, Sections};
use crate::section_kind::{AskError, RequestSite};
use crate::sections::SECTIONS;
use crate::shading_model::ShadingModel;
use crate::surface_sampler::SurfaceSampler;
use crate::SceneError;
use std::path::{Path, PathBuf};
use thiserror::Error;

/// Point lights of the bench scene when the request does not say (the seed scene's:
/// `SEED_LIGHT_COUNT`).
pub const BENCH_LIGHTS: u64 = 1024;

/// Which scene.
#[derive(Clone, Debug, PartialEq)]
pub enum SceneSource {
    /// The built-in 7×7 grid of one object kind in one material (with a floor under it for
    /// the blinn-phong model, whose sun casts shadows).
    Seed { object: MeshKind, material: Material },
    /// The closed room with a pillar and one light (`Scene::shadow_room`); keeps its light.
    Room,
    /// The benchmark scene (bench_scene.rs) with `objects` objects: random lights whose radius
    /// follows their count; the request's layout and radius do not apply.
    Bench { objects: usize },
    /// A scene file (`.toml`) or a glTF file (anything else: `.gltf`, `.glb`).
    File(PathBuf),
}

/// A scene to build.
#[derive(Clone, Debug, PartialEq)]
pub struct SceneRequest {
    pub source: SceneSource,
    /// Point lights: None keeps the scene's own (the seed scene 64, the bench scene 1024, a
    /// file its own, or the default rig where it has none); Some(n) places n lights by
    /// `layout`, `seed` and `radius` (a file's lights and spot cones are then replaced). The
    /// seed scene places them in its fixed frame, a file in a frame fitted to its box.
    pub lights: Option<u64>,
    pub layout: LightLayout,
    /// Seed of the random and surface layouts and of radii drawn from a range.
    pub seed: u64,
    /// None: the seed scene's 15, or for a file the radius fitted to its frame and the count
    /// (`LightFrame::default_radius`).
    pub radius: Option<RadiusRange>,
    /// The shading model; None: the file's, else the seed model.
    pub shading: Option<ShadingModel>,
    /// Where the camera stands and looks (its planes fitted to the scene's box as a scene
    /// file's are); None: the scene's own camera.
    pub camera: Option<CameraSpec>,
    /// Draw every point light as a small glowing cube (`Scene::with_light_markers`).
    pub show_lights: bool,
    /// Width over height of the image the scene is seen in: a file without a camera is framed
    /// for it (`framing::frame_scene`).
    pub aspect: f32,
    /// Percent of the scene's objects made transparent (`transparency::make_transparent`).
    pub transparent_percent: u32,
    /// Panes of glass added across the whole view (`transparency::add_glass_layers`).
    pub glass_layers: u32,
    /// Colours of the lights placed by layout; None: the seed scene's palette, near-white in
    /// a file (`LightColors`).
    pub light_colors: Option<LightColors>,
    /// What it asks of the features' sections of the scene, each in its feature's type
    /// (`section_kind`; the environment light's `EnvironmentAsk`).
    pub sections: Sections,
    /// A glTF file's material variant to draw (KHR_materials_variants), by name.
    pub variant: Option<String>,
}

/// A built scene and the shading model to render it with.
#[derive(Clone, Debug, PartialEq)]
pub struct BuiltScene {
    pub scene: Scene,
    pub shading: ShadingModel,
    pub warnings: Vec<SceneWarning>,
}

/// Something about a built scene its user should hear of.
#[derive(Clone, Debug, PartialEq, Error)]
pub enum SceneWarning {
    /// What a file holds that is left out.
    #[error("'{}': {message}", path.display())]
    Left { path: PathBuf, message: String },
    /// A file's scene without any light, lit by the default rig instead: DEFAULT_RIG_LIGHTS
    /// lights of the request's layout (the seed's grid unless it says otherwise) fitted to the
    /// scene's box.
    #[error("'{}': the scene has no lights: added {lights} point lights ({} layout, radius {radius:.3}) fitted to its box", path.display(), layout.name())]
    DefaultRig { path: PathBuf, lights: u32, layout: LightLayout, radius: f32 },
}

/// Why a requested scene could not be built.
#[derive(Debug, Error)]
pub enum SceneRequestError {
    #[error(transparent)]
    Scene(#[from] SceneError),
    #[error(transparent)]
    SceneFile(#[from] SceneFileError),
    #[error(transparent)]
    Gltf(#[from] GltfFileError),
    /// A file naming a shading model that does not exist.
    #[error("'{}': shading model: {problem}", path.display())]
    FileShading { path: PathBuf, problem: SceneError },
    /// A file whose box fits its lights no radius.
    #[error("'{}': {problem}", path.display())]
    FileLights { path: PathBuf, problem: SceneError },
    /// What a feature's section was asked for and cannot be (an environment file that does
    /// not load).
    #[error("{0}")]
    Section(AskError),
}

impl SceneRequest {
    /// `source` with the defaults: its own lights (placed as the seed's grid, seed 1, the
    /// default radius where a count is given), its own shading model.
    pub fn new(source: SceneSource) -> SceneRequest {
        SceneRequest {
            source,
            lights: None,
            layout: LightLayout::Grid,
            seed: 1,
            radius: None,
            shading: None,
            camera: None,
            show_lights: false,
            aspect: DEFAULT_ASPECT,
            transparent_percent: 0,
            glass_layers: 0,
            light_colors: None,
            sections: Sections::default(),
            variant: None,
        }
    }

    /// The request with `ask` as what it asks of its feature's section (replacing an earlier
    /// ask of that feature).
    pub fn asking<T: Section>(mut self, ask: T) -> SceneRequest {
        self.sections.set(Some(ask));
        self
    }

    /// Whether the scene is the seed's grid (its object and material may change).
    pub fn is_seed(&self) -> bool {
        matches!(self.source, SceneSource::Seed { .. })
    }

    /// `count` lights of the request's layout with `radius` unless the request names one.
    fn lights_of(&self, count: u64, radius: impl FnOnce(u32) -> Result<f32, SceneError>) -> Result<LightParams, SceneError> {
        let count = LightParams::check_count(count)?;
        let radius = match self.radius {
            Some(range) => range,
            None => RadiusRange::fixed(radius(count)?),
        };
        Ok(LightParams { count, layout: self.layout, seed: self.seed, radius })
    }

    pub fn build(&self) -> Result<BuiltScene, SceneRequestError> {
        let mut built = self.build_scene()?;
        if let Some(spec) = &self.camera {
            built.scene.camera = spec.camera(built.scene.bounds());
            built.scene.camera_framed = false;
        }
        if self.show_lights {
            built.scene = built.scene.with_light_markers()?;
        }
        crate::transparency::make_transparent(&mut built.scene, self.transparent_percent);
        crate::transparency::add_glass_layers(&mut built.scene, self.glass_layers, self.aspect);
        let site = RequestSite { shading: built.shading };
        for kind in SECTIONS {
            (kind.apply)(&self.sections, &mut built.scene, &site).map_err(SceneRequestError::Section)?;
        }
        Ok(built)
    }

    fn build_scene(&self) -> Result<BuiltScene, SceneRequestError> {
        let model = self.shading.unwrap_or(ShadingModel::Seed);
        let built = |scene| BuiltScene { scene, shading: model, warnings: Vec::new() };
        match &self.source {
            SceneSource::Room => Ok(built(Scene::shadow_room())),
            SceneSource::Bench { objects } => {
                let count = LightParams::check_count(self.lights.unwrap_or(BENCH_LIGHTS))?;
                Ok(built(bench_scene(count, self.seed, *objects)?))
            }
            SceneSource::Seed { object, material } => {
                // The seed's 15 up to its 64 lights; beyond, a radius that follows the count in
                // a frame of layers (LightFrame::seed), so that any count renders in bounded time.
                let mut scene = Scene::seed_objects(*object, *material);
                let count = self.lights.unwrap_or(u64::from(SEED_LIGHT_COUNT));
                let frame = LightFrame::seed(u32::try_from(count).unwrap_or(u32::MAX));
                let area = || scene.surfaces().as_ref().map_or(0.0, SurfaceSampler::area);
                let params = self.lights_of(count, |n| {
                    if n <= SEED_LIGHT_COUNT {
                        Ok(SEED_RADIUS)
                    } else {
                        frame.fitted_radius(self.layout, n, if self.layout == LightLayout::Surface { area() } else { 0.0 })
                    }
                })?;
                scene.lights = scene.build_lights(&params, &frame)?;
                self.light_colors.unwrap_or(LightColors::Palette).paint(&mut scene.lights);
                Ok(built(if model == ShadingModel::BlinnPhong { scene.with_floor() } else { scene }))
            }
            SceneSource::File(path) => self.build_file(path),
        }
    }

    fn build_file(&self, path: &Path) -> Result<BuiltScene, SceneRequestError> {
        let is_toml = path.to_string_lossy().to_lowercase().ends_with(".toml");
        // A section the request replaces is the request's: the file's table is only checked.
        let replaced: Vec<&str> = SECTIONS.iter().filter(|kind| (kind.replaces_file)(&self.sections)).map(|kind| kind.table).collect();
        let file = if is_toml { scene_file::load_with(path, &replaced)? } else { gltf_scene::load(path, self.variant.as_deref())? };
        let path = path.to_path_buf();
        let shading = match (self.shading, &file.shading) {
            (Some(model), _) => model,
            (None, Some(name)) => {
                ShadingModel::from_name(name).map_err(|problem| SceneRequestError::FileShading { path: path.clone(), problem })?
            }
            (None, None) => ShadingModel::Seed,
        };
        let mut warnings: Vec<SceneWarning> =
            file.warnings.into_iter().map(|message| SceneWarning::Left { path: path.clone(), message }).collect();
        let mut scene = file.scene;
        // A file without a camera came with one framing it for a default-sized image: frame it
        // for this one (unless `--camera` replaces it anyway).
        if scene.camera_framed && self.aspect != DEFAULT_ASPECT && self.camera.is_none() {
            scene.camera = frame_scene(&scene, self.aspect, scene.camera.fov_y_deg);
        }
        let unlit = scene.lights.is_empty() && scene.directional.is_empty();
        if unlit {
            let site = RequestSite { shading };
            for kind in SECTIONS {
                (kind.unlit_file)(&self.sections, &mut scene, &site);
            }
        }
        if self.lights.is_some() || unlit {
            let count = self.lights.unwrap_or(DEFAULT_RIG_LIGHTS as u64);
            let (lo, hi) = scene.bounds();
            let frame = LightFrame::around(lo, hi);
            let surfaces = if self.layout == LightLayout::Surface { scene.surfaces() } else { None };
            let area = surfaces.as_ref().map_or(0.0, SurfaceSampler::area);
            let params = self.lights_of(count, |n| frame.fitted_radius(self.layout, n, area)).map_err(|problem| match problem {
                SceneError::FittedRadius(_) => SceneRequestError::FileLights { path: path.clone(), problem },
                other => other.into(),
            })?;
            scene.lights = params.build_in(&frame, surfaces.as_ref())?;
            self.light_colors.unwrap_or(LightColors::White).paint(&mut scene.lights);
            scene.light_motion = frame.motion();
            // The file's spot cones belonged to its own lights.
            scene.cones.clear();
            if self.lights.is_none() {
                warnings.push(SceneWarning::DefaultRig {
                    path: path.clone(),
                    lights: params.count,
                    layout: self.layout,
                    radius: params.radius.max,
                });
            }
        }
        Ok(BuiltScene { scene, shading, warnings })
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::bench_scene::BENCH_OBJECTS;

    fn seed() -> SceneSource {
        SceneSource::Seed { object: MeshKind::Sphere, material: Material::named("gold").unwrap() }
    }

    #[test]
    fn the_seed_scene_has_its_lights_and_a_floor_under_blinn_phong() {
        let plain = SceneRequest::new(seed()).build().unwrap();
        assert_eq!((plain.scene.lights.len(), plain.scene.objects.len(), plain.shading), (64, 49, ShadingModel::Seed));
        let lit = SceneRequest { shading: Some(ShadingModel::BlinnPhong), lights: Some(5), ..SceneRequest::new(seed()) }.build().unwrap();
        assert_eq!((lit.scene.lights.len(), lit.scene.objects.len(), lit.shading), (5, 50, ShadingModel::BlinnPhong));
        assert!(lit.warnings.is_empty());
    }

    #[test]
    fn room_and_bench_keep_their_own_lights_and_bench_takes_a_count() {
        let room = SceneRequest { lights: Some(9), ..SceneRequest::new(SceneSource::Room) }.build().unwrap();
        assert_eq!(room.scene, Scene::shadow_room());
        let bench = SceneRequest { lights: Some(300), seed: 3, ..SceneRequest::new(SceneSource::Bench { objects: BENCH_OBJECTS }) }
            .build()
            .unwrap();
        assert_eq!(bench.scene, bench_scene(300, 3, BENCH_OBJECTS).unwrap());
        assert_eq!(SceneRequest::new(SceneSource::Bench { objects: BENCH_OBJECTS }).build().unwrap().scene.lights.len(), 1024);
    }

    #[test]
    fn light_counts_out_of_range_are_refused() {
        let e = SceneRequest { lights: Some(0), ..SceneRequest::new(seed()) }.build().unwrap_err();
        assert!(matches!(e, SceneRequestError::Scene(SceneError::LightCount(0))), "{e}");
    }

    #[test]
    fn a_file_names_its_model_keeps_or_replaces_its_lights_and_says_what_is_missing() {
        let dir = std::env::temp_dir().join(format!("ml-scene-request-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let file = |name: &str, text: &str| {
            let path = dir.join(name);
            std::fs::write(&path, text).unwrap();
            SceneRequest::new(SceneSource::File(path))
        };
        let dark = file("dark.toml", "[shading]\nmodel = \"pbr\"\n[[objects]]\nmesh = \"sphere\"\n");
        let built = dark.build().unwrap();
        assert_eq!(built.shading, ShadingModel::Pbr);
        // No light in the file: the default rig, fitted to the unit sphere's box.
        let radius = LightFrame::around(glam::Vec3::splat(-1.0), glam::Vec3::ONE).default_radius(LightLayout::Grid, 64, 0.0);
        let rig = SceneWarning::DefaultRig { path: dir.join("dark.toml"), lights: 64, layout: LightLayout::Grid, radius };
        assert_eq!(built.warnings, [rig]);
        assert_eq!(built.scene.lights.len(), 64);
        // The grid's first layer hangs over the sphere, the others reach down through its box,
        // each light moved about within its cell (never above the grid), near-white.
        let top = built.scene.lights.iter().map(|l| l.position_radius[1]).fold(f32::MIN, f32::max);
        assert!(top > 1.2 && top <= 1.5, "{top}");
        assert!(built.scene.lights.iter().all(|l| l.position_radius[1] <= 1.5 && l.position_radius[3] == radius));
        assert!(built.scene.lights.iter().all(|l| l.color[..3].iter().all(|&c| c > 0.8)), "near-white lights");
        // Framed for a default-sized image; asked for another aspect, framed for that one.
        let framed = crate::framing::frame_scene(&built.scene, DEFAULT_ASPECT, 60.0);
        assert_eq!(built.scene.camera, framed);
        let tall = SceneRequest { aspect: 0.5, ..dark.clone() }.build().unwrap();
        assert_eq!(tall.scene.camera, crate::framing::frame_scene(&built.scene, 0.5, 60.0));
        assert!(tall.scene.camera.position.distance(glam::Vec3::ZERO) > framed.position.distance(glam::Vec3::ZERO));
        let lit = SceneRequest { lights: Some(4), shading: Some(ShadingModel::Seed), ..dark }.build().unwrap();
        assert_eq!((lit.scene.lights.len(), lit.shading), (4, ShadingModel::Seed));
        assert!(lit.warnings.is_empty());
        let odd = file("odd.toml", "[shading]\nmodel = \"phong\"\n[[objects]]\nmesh = \"sphere\"\n");
        let e = odd.build().unwrap_err().to_string();
        assert!(e.ends_with("odd.toml': shading model: unknown shading model 'phong': expected one of seed, blinn-phong, pbr"), "{e}");
        // Asked for another model, the file's unknown one does not matter.
        assert!(SceneRequest { shading: Some(ShadingModel::Pbr), ..odd }.build().is_ok());
        let e = file("empty.glb", "").build().unwrap_err().to_string();
        assert!(e.starts_with("glTF file '") && e.ends_with("empty.glb': the file is empty"), "{e}");
    }

    #[test]
    fn an_environment_asked_for_replaces_the_files_without_reading_its_image() {
        use crate::environment::{Environment, EnvironmentAsk, EnvironmentSource};
        let dir = std::env::temp_dir().join(format!("ml-scene-request-env-{}", std::process::id()));
        std::fs::create_dir_all(&dir).unwrap();
        let path = dir.join("lit.toml");
        let text = "[environment]\nfile = \"missing.hdr\"\nintensity = 2.0\n[[objects]]\nmesh = \"sphere\"\n";
        std::fs::write(&path, text).unwrap();
        let own = SceneRequest::new(SceneSource::File(path.clone()));
        let e = own.build().unwrap_err().to_string();
        assert!(e.contains("missing.hdr"), "the file's own image is read: {e}");
        let sky =
            |request: &SceneRequest| request.clone().asking(EnvironmentAsk { source: Some(EnvironmentSource::Sky), ..Default::default() });
        let replaced = sky(&own).build().unwrap();
        let env = replaced.scene.sections.get::<Environment>().expect("the sky asked for");
        assert_eq!(env.intensity, Environment::sky().intensity, "the file's intensity went with its image");
        // The file's numbers are checked all the same.
        std::fs::write(&path, text.replace("2.0", "-1.0")).unwrap();
        assert!(sky(&own).build().is_err());
        std::fs::remove_dir_all(&dir).unwrap();
    }
}
