//! Writes the seed inputs of the fuzz targets that the writer's own (crates/ml-cpu/examples/
//! fuzz_seeds.rs) do not give: a glTF naming its buffer and image as files of the fixture
//! folder, and scene files naming its glTF models. Usage: seeds GLTF_DIR SCENE_DIR
use std::path::PathBuf;

fn main() {
    let dirs: Vec<PathBuf> = std::env::args().skip(1).map(PathBuf::from).collect();
    let [gltf, scene] = &dirs[..] else {
        eprintln!("usage: seeds GLTF_DIR SCENE_DIR");
        std::process::exit(2);
    };
    for dir in [gltf, scene] {
        std::fs::create_dir_all(dir).expect("a seed folder");
    }
    let files = manylights_fuzz::folder_files();
    let external = files.iter().find(|(name, _)| *name == "quad.gltf").expect("the fixture's glTF");
    std::fs::write(gltf.join("external.gltf"), &external.1).expect("write");
    std::fs::write(gltf.join("textured.gltf"), manylights_fuzz::textured_quad().to_gltf()).expect("write");
    let scenes = [
        ("models.toml", "[[objects]]\ngltf = \"quad.glb\"\nposition = [1.0, 0.0, 0.0]\nscale = 2.0\n[[objects]]\ngltf = \"quad.gltf\"\n[[objects]]\nmesh = \"cube\"\nposition = [0.0, -1.0, 0.0]\n"),
        ("outside.toml", "[[objects]]\ngltf = \"../quad.glb\"\n"),
    ];
    for (name, text) in scenes {
        std::fs::write(scene.join(name), text).expect("write");
    }
    // What the targets make of them: the models load from the fixture folder, the one outside
    // it is refused.
    let folder = Some(manylights_fuzz::folder());
    ml_cpu::gltf_scene::from_bytes(&external.1, folder).expect("the external glTF loads");
    ml_cpu::scene_file::from_bytes(scenes[0].1.as_bytes(), folder).expect("the models load");
    let outside = ml_cpu::scene_file::from_bytes(scenes[1].1.as_bytes(), folder).err().map(|e| e.to_string());
    assert!(outside.as_deref().is_some_and(|e| e.contains("leads out of the folder")), "{outside:?}");
}
