//! Scene files (issue 7): the committed `scenes/seed.toml` renders the built-in seed scene's
//! image (SPEC §1), through the same renderer (≤ 1/255; measured: identical).

mod common;

use ml_cpu::lights::LightParams;
use ml_cpu::material::Material;
use ml_cpu::mesh::MeshKind;
use ml_cpu::scene::Scene;
use ml_cpu::scene_file;
use std::path::Path;

#[test]
fn the_seed_scene_file_renders_the_seed_scene() {
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/seed.toml");
    let file = scene_file::load(&path).expect("scenes/seed.toml");
    let seed = Scene::seed(MeshKind::Sphere, Material::named("gold").unwrap(), &LightParams::seed_default()).unwrap();
    let settings = common::settings(160, 90);
    let outputs = [common::render(file.scene, settings), common::render(seed, settings)];
    let (max, differing) = common::max_difference(&outputs[0], &outputs[1]);
    println!("scene file vs built-in: max {max}/255, {differing} pixels differ");
    assert!(max <= 1, "the scene file's image differs by {max}/255");
    // Not a blank frame: the spheres are lit.
    assert!(outputs[0].rgba.chunks_exact(4).filter(|p| p[0] > 60).count() > 200);
}
