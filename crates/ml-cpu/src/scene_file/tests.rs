use super::*;
use crate::gpu_types::LightCone;
use crate::lights::LightParams;

const MINIMAL: &str = "[[objects]]\nmesh = \"sphere\"\n";

#[test]
fn only_objects_are_required() {
    let f = parse(MINIMAL).unwrap();
    assert_eq!(f.shading, None);
    let s = &f.scene;
    assert_eq!(s.objects.len(), 1);
    assert_eq!(s.objects[0], Object::placed(MeshKind::Sphere, Vec3::ZERO, 1.0, Material::named("white").unwrap()));
    assert!(s.lights.is_empty());
    assert_eq!(s.ambient, SEED_AMBIENT);
    // The default camera frames the object for a default-sized image: the sphere's centre is
    // ahead of it, all of the sphere in view, filling most of the image's height.
    let c = &s.camera;
    assert!((c.forward() - (Vec3::ZERO - c.position).normalize()).length() < 0.05);
    let view_proj = c.projection(crate::framing::DEFAULT_ASPECT) * c.view();
    let (mut y0, mut y1) = (f32::MAX, f32::MIN);
    for v in MeshKind::Sphere.build().vertices {
        let p = view_proj.project_point3(Vec3::from(v.position));
        assert!(p.x.abs() <= 1.0 && p.y.abs() <= 1.0 && (0.0..=1.0).contains(&p.z), "{:?} → {p}", v.position);
        (y0, y1) = (y0.min(p.y), y1.max(p.y));
    }
    assert!((y1 - y0) * 0.5 >= 0.7, "the sphere spans {} of the height", (y1 - y0) * 0.5);
}

#[test]
fn every_field_is_read() {
    let text = r#"
[camera]
position = [0.0, 2.0, 6.0]
target = [0.0, 0.0, 0.0]
fov_y_deg = 50.0
near = 0.5
far = 100.0
[shading]
model = "pbr"
ambient = 0.05
[[lights]]
position = [1.0, 3.0, 2.0]
color = [1.0, 0.5, 0.2]
radius = 12.0
[[lights]]
kind = "point"
position = [-1.0, 3.0, 2.0]
[[lights]]
kind = "directional"
direction = [0.0, -2.0, 0.0]
color = [0.5, 0.5, 0.5]
[[lights]]
kind = "spot"
position = [0.0, 4.0, 0.0]
direction = [0.0, -1.0, 0.0]
inner_deg = 10.0
outer_deg = 20.0
[[objects]]
mesh = "teapot"
position = [1.0, 0.0, 0.0]
scale = 2.0
material = { albedo = [1.0, 0.765557, 0.336057], roughness = 0.5, metallic = 1.0 }
[[objects]]
mesh = "plane"
material = { name = "copper", roughness = 0.3 }
"#;
    let f = parse(text).unwrap();
    assert_eq!(f.shading.as_deref(), Some("pbr"));
    let s = &f.scene;
    assert_eq!(s.ambient, 0.05);
    assert_eq!(s.camera, Camera::looking_at(Vec3::new(0.0, 2.0, 6.0), Vec3::ZERO, 50.0, 0.5, 100.0));
    assert_eq!(s.lights[0], PointLight { position_radius: [1.0, 3.0, 2.0, 12.0], color: [1.0, 0.5, 0.2, 0.0] });
    assert_eq!(s.lights[1], PointLight { position_radius: [-1.0, 3.0, 2.0, SEED_RADIUS], color: [1.0, 1.0, 1.0, 0.0] });
    assert_eq!(s.directional, vec![crate::scene::DirectionalLight { direction: -Vec3::Y, color: Vec3::splat(0.5) }]);
    // With a spot among them, every light has a cone: none for the point lights.
    let spot = LightCone::spot(-Vec3::Y, 10f32.to_radians(), 20f32.to_radians());
    assert_eq!(s.cones, vec![LightCone::NONE, LightCone::NONE, spot]);
    assert_eq!(s.lights[2].position_radius, [0.0, 4.0, 0.0, SEED_RADIUS]);
    assert_eq!(s.objects[0].mesh, MeshKind::Teapot);
    assert_eq!(s.objects[0].as_placed(), Some((Vec3::X, 2.0)));
    assert_eq!(s.objects[0].material, Material { albedo: Vec3::new(1.0, 0.765557, 0.336057), roughness: 0.5, metallic: 1.0 });
    let copper = Material::named("copper").unwrap();
    assert_eq!(s.objects[1].material, Material { roughness: 0.3, ..copper });
}

#[test]
fn the_seed_scene_survives_a_round_trip() {
    let seed = Scene::seed(MeshKind::Sphere, Material::named("gold").unwrap(), &LightParams::seed_default()).unwrap();
    let target = seed.camera.position + seed.camera.forward() * 10.0;
    let f = parse(&to_toml(&seed, "seed", target)).unwrap();
    assert_eq!(f.shading.as_deref(), Some("seed"));
    assert_eq!(f.scene.objects, seed.objects);
    assert_eq!(f.scene.lights, seed.lights);
    assert_eq!(f.scene.ambient, seed.ambient);
    let (a, b) = (f.scene.camera, seed.camera);
    assert_eq!((a.position, a.fov_y_deg, a.near, a.far), (b.position, b.fov_y_deg, b.near, b.far));
    assert!((a.pitch_deg - b.pitch_deg).abs() < 1e-4 && (a.yaw_deg - b.yaw_deg).abs() < 1e-4, "{a:?} vs {b:?}");
}

// The broken texts (each with its expected error, through the binary and its exit code):
// crates/manylights/tests/command_line/cli.rs.

#[test]
fn files_that_are_no_scene_files_are_refused() {
    let dir = std::env::temp_dir().join(format!("manylights-scene-file-{}", std::process::id()));
    std::fs::create_dir_all(&dir).unwrap();
    let err = |p: &Path| load(p).unwrap_err().to_string();
    assert!(err(&dir).contains("a directory"));
    assert!(err(&dir.join("missing.toml")).contains("cannot read it"));
    let binary = dir.join("binary.toml");
    std::fs::write(&binary, [0x5b, 0xff, 0xfe, 0x00]).unwrap();
    assert!(err(&binary).contains("not UTF-8"));
    let huge = dir.join("huge.toml");
    let f = std::fs::File::create(&huge).unwrap();
    f.set_len(MAX_FILE_BYTES + 1).unwrap(); // sparse: nothing written, nothing read
    let e = err(&huge);
    assert!(e.contains("more than the") && e.contains("huge.toml"), "{e}");
    std::fs::remove_dir_all(&dir).unwrap();
}

/// `scenes/seed.toml`, the seed scene as a scene file (the render tests draw both and compare
/// them): it must hold exactly the built-in scene. `WRITE_SCENES=1` writes it anew.
#[test]
fn the_committed_seed_scene_file_is_the_seed_scene() {
    let seed = Scene::seed(MeshKind::Sphere, Material::named("gold").unwrap(), &LightParams::seed_default()).unwrap();
    let path = Path::new(env!("CARGO_MANIFEST_DIR")).join("../../scenes/seed.toml");
    if std::env::var_os("WRITE_SCENES").is_some() {
        let header = "# The built-in seed scene as a scene file: 7×7 gold spheres, the seed scene's 64 lights and\n# camera. `manylights render --scene scenes/seed.toml` renders what `--scene seed` does.\n\n";
        let target = seed.camera.position + seed.camera.forward() * 10.0;
        std::fs::write(&path, format!("{header}{}", to_toml(&seed, "seed", target))).unwrap();
    }
    let f = load(&path).unwrap();
    assert_eq!(f.scene.objects, seed.objects);
    assert_eq!(f.scene.lights, seed.lights);
    assert_eq!(f.shading.as_deref(), Some("seed"));
}

#[test]
fn gltf_objects_bring_their_meshes_placed_by_the_scene_file() {
    use crate::gltf_writer::{quad, GltfWriter, PrimitiveData};
    let dir = std::env::temp_dir().join(format!("manylights-scene-gltf-{}", std::process::id()));
    std::fs::create_dir_all(dir.join("models")).unwrap();
    let mut w = GltfWriter::new();
    let m = w.material([0.5, 0.25, 1.0, 1.0], 0.0, 0.5);
    w.json["materials"][m]["extensions"] = serde_json::json!({ "KHR_materials_volume": { "thicknessFactor": 0.25 } });
    let mesh = w.mesh(&[PrimitiveData { material: Some(m), ..quad() }]);
    w.node(serde_json::json!({ "mesh": mesh, "translation": [0.0, 1.0, 0.0] }), true);
    std::fs::write(dir.join("models/quad.glb"), w.to_glb()).unwrap();
    let text = "[[objects]]\nmesh = \"cube\"\n[[objects]]\ngltf = \"models/quad.glb\"\nposition = [10.0, 0.0, 0.0]\nscale = 2.0\n[[objects]]\ngltf = \"models/quad.glb\"\n";
    std::fs::write(dir.join("scene.toml"), text).unwrap();
    let f = load(&dir.join("scene.toml")).unwrap();
    let s = &f.scene;
    assert_eq!(s.objects.len(), 3);
    // A file placed twice is loaded once: both placements are instances of its one mesh.
    assert_eq!(s.meshes.len(), 1, "each placement brought its own copy");
    assert_eq!(s.objects[1].mesh, MeshKind::Loaded(0));
    assert_eq!(s.objects[2].mesh, MeshKind::Loaded(0));
    assert_eq!(s.objects[1].material.albedo, Vec3::new(0.5, 0.25, 1.0));
    // The glTF node's (0, 1, 0), scaled by 2 and moved by 10 in x.
    assert!((s.objects[1].position() - Vec3::new(10.0, 2.0, 0.0)).length() < 1e-5, "{}", s.objects[1].position());
    assert!((s.objects[2].position() - Vec3::new(0.0, 1.0, 0.0)).length() < 1e-5);
    // A volume's thickness scales with its placement, as its geometry does.
    assert_eq!((s.objects[1].extras.lobes.thickness, s.objects[2].extras.lobes.thickness), (0.5, 0.25));
    // 800 placements (a 12 MB model placed so used to hold 800 copies): one mesh, 800 objects.
    let many: String = (0..800).map(|i| format!("[[objects]]\ngltf = \"models/quad.glb\"\nposition = [{i}.0, 0.0, 0.0]\n")).collect();
    std::fs::write(dir.join("many.toml"), many).unwrap();
    let f = load(&dir.join("many.toml")).unwrap();
    assert_eq!((f.scene.meshes.len(), f.scene.objects.len()), (1, 800));
    assert!((f.scene.objects[799].position() - Vec3::new(799.0, 1.0, 0.0)).length() < 1e-3);
    // Refused: a material on it, a missing file, no folder to look in.
    std::fs::write(dir.join("bad.toml"), "[[objects]]\ngltf = \"models/quad.glb\"\nmaterial = { roughness = 0.5 }\n").unwrap();
    let in_first_object = |e: SceneFileProblem| match e {
        SceneFileProblem::In { entry: Entry::Object(0), problem } => *problem,
        other => panic!("{other}"),
    };
    let problem = in_first_object(load(&dir.join("bad.toml")).unwrap_err().problem);
    assert!(matches!(problem, SceneFileProblem::GltfMaterial), "{problem}");
    std::fs::write(dir.join("missing.toml"), "[[objects]]\ngltf = \"nope.gltf\"\n").unwrap();
    let problem = in_first_object(load(&dir.join("missing.toml")).unwrap_err().problem);
    assert!(problem.to_string().starts_with("'nope.gltf': cannot read it"), "{problem}");
    let problem = in_first_object(parse("[[objects]]\ngltf = \"a.gltf\"\n").unwrap_err());
    assert!(matches!(problem, SceneFileProblem::NoFolder), "{problem}");
    std::fs::remove_dir_all(&dir).unwrap();
}

#[test]
fn spot_and_directional_lights_survive_a_round_trip() {
    let text = "[[objects]]\nmesh = \"plane\"\n[[lights]]\nposition = [0.0, 2.0, 0.0]\n[[lights]]\nkind = \"spot\"\nposition = [1.0, 3.0, 0.0]\ndirection = [0.0, -1.0, 0.0]\ninner_deg = 15.0\nouter_deg = 35.0\n[[lights]]\nkind = \"directional\"\ndirection = [1.0, -1.0, 0.0]\n";
    let first = parse(text).unwrap().scene;
    let again = parse(&to_toml(&first, "pbr", Vec3::ZERO)).unwrap().scene;
    assert_eq!(again.lights, first.lights);
    assert_eq!(again.directional.len(), 1);
    assert!((again.directional[0].direction - first.directional[0].direction).length() < 1e-6);
    for (a, b) in again.cones.iter().zip(&first.cones) {
        let close = |x: &[f32; 4], y: &[f32; 4]| x.iter().zip(y).all(|(p, q)| (p - q).abs() <= 1e-3 * q.abs().max(1.0));
        assert!(close(&a.direction_scale, &b.direction_scale) && close(&a.offset, &b.offset), "{a:?} vs {b:?}");
    }
    assert_eq!(again.cones.len(), 2);
}

/// A scene file, or a glTF it names, that is a device or a pipe is refused at once with the
/// line that says so (read whole, /dev/zero would fill the memory; a pipe no one writes to
/// would wait forever).
#[cfg(unix)]
#[test]
fn devices_and_pipes_are_refused_at_once() {
    use crate::files::hostile::{fifo, folder, link, refused_at_once};
    let d = folder("scene-devices");
    let not_regular = "it is not a regular file (a device, pipe or socket)";
    for file in [fifo(&d, "pipe.toml"), link(&d, "zero.toml", "/dev/zero"), PathBuf::from("/dev/zero")] {
        refused_at_once(&file.display().to_string(), &format!("scene file '{}': {not_regular}", file.display()), || load(&file).map(drop));
    }
    fifo(&d, "pipe.glb");
    std::fs::write(d.join("scene.toml"), "[[objects]]\ngltf = \"pipe.glb\"\n").unwrap();
    refused_at_once("a glTF on a pipe", &format!("objects[0]: 'pipe.glb': {not_regular}"), || load(&d.join("scene.toml")).map(drop));
}

/// The glTF files a scene file names are read only inside its folder: absolute paths, `..`
/// that climbs out and links that end outside are refused, naming the reference and nothing
/// of the file outside.
#[cfg(unix)]
#[test]
fn gltf_objects_stay_inside_the_scene_folder() {
    use crate::files::hostile::{folder, link};
    use crate::gltf_writer::{quad, GltfWriter};
    let d = folder("scene-references");
    let scenes = d.join("scenes");
    std::fs::create_dir_all(scenes.join("models")).unwrap();
    let mut w = GltfWriter::new();
    let mesh = w.mesh(&[quad()]);
    w.node(serde_json::json!({ "mesh": mesh }), true);
    std::fs::write(scenes.join("models/quad.glb"), w.to_glb()).unwrap();
    std::fs::write(d.join("outside.glb"), w.to_glb()).unwrap();
    link(&scenes, "out.glb", d.join("outside.glb"));
    link(&scenes, "zero.glb", "/dev/zero");
    link(&scenes, "in.glb", scenes.join("models/quad.glb"));
    let scene = |gltf: &str| {
        std::fs::write(scenes.join("scene.toml"), format!("[[objects]]\ngltf = \"{gltf}\"\n")).unwrap();
        load(&scenes.join("scene.toml")).map(drop)
    };
    let size = std::fs::metadata(d.join("outside.glb")).unwrap().len().to_string();
    for (gltf, expected) in [
        ("../outside.glb", "objects[0]: '../outside.glb': it leads out of the folder of the file that names it"),
        ("models/../../outside.glb", "it leads out of the folder"),
        ("out.glb", "'out.glb': it leads out of the folder"),
        ("zero.glb", "'zero.glb': it leads out of the folder"),
        ("/dev/zero", "'/dev/zero': an absolute path"),
    ] {
        let e = scene(gltf).unwrap_err().to_string();
        // The size as a number of its own: the folder's name holds the process id, whose digits
        // may contain it.
        let discloses = e.split(|c: char| !c.is_ascii_digit()).any(|n| n == size);
        assert!(e.contains(expected) && !discloses, "{gltf}: {e}");
    }
    for gltf in ["models/quad.glb", "./models/../models/quad.glb", "in.glb"] {
        scene(gltf).unwrap_or_else(|e| panic!("{gltf}: {e}"));
    }
}

/// Values a scene file used to pass silently, each refused with one line naming the field:
/// arrays of more than three numbers, and numbers finite but out of the range that renders.
#[test]
fn values_out_of_range_are_refused_naming_the_field() {
    let sphere = "[[objects]]\nmesh = \"sphere\"\n";
    let light = |field: &str| format!("{sphere}[[lights]]\nposition = [0.0, 3.0, 0.0]\n{field}\n");
    let cases = [
        (format!("{sphere}position = [1.0, 2.0, 3.0, 4.0]\n"), "line 3: more than 3 numbers"),
        (format!("{sphere}scale = 1e38\n"), "objects[0]: scale 1e38 is out of range: use 1e-6 to 1000000"),
        (format!("{sphere}scale = 1e-38\n"), "objects[0]: scale 1e-38 is out of range"),
        (format!("{sphere}position = [1e38, 0.0, 0.0]\n"), "objects[0]: position 1e38 is out of range: use -1000000 to 1000000"),
        (format!("{sphere}position = [900000.0, 0.0, 0.0]\nscale = 200000.0\n"), "the scene's objects reach 1100000, beyond ±1000000"),
        (format!("{sphere}position = [1000000.0, 0.0, 0.0]\nscale = 0.000001\n"), "too small to render"),
        (format!("{sphere}material = {{ albedo = [2.0, 0.0, 0.0] }}\n"), "material albedo 2 must lie in [0, 1]"),
        (light("color = [1e38, 0.0, 0.0]"), "lights[0]: color 1e38 is out of range: use 0 to 1e7"),
        (light("radius = 1e38"), "lights[0]: radius 1e38 is out of range"),
        (light("radius = 1e-38"), "lights[0]: radius 1e-38 is out of range"),
        (format!("{sphere}[[lights]]\nposition = [0.0, 1e38, 0.0]\n"), "lights[0]: position 1e38 is out of range"),
        (format!("{sphere}[[lights]]\nkind = \"directional\"\ndirection = [1e38, -1e38, 0.0]\n"), "direction 1e38 is out of range"),
        (format!("{sphere}[shading]\nambient = 1e38\n"), "[shading] ambient 1e38 is out of range"),
        (format!("{sphere}[camera]\nnear = 1e-38\n"), "[camera] near 1e-38 is out of range"),
        (format!("{sphere}[camera]\nfov_y_deg = 1e-30\n"), "must be at least 0.01 and below 180"),
        (format!("{sphere}[camera]\nfov_y_deg = 40.0\northo_half_height = 3.0\n"), "fov_y_deg and ortho_half_height together"),
        (format!("{sphere}[camera]\nfar = 1e38\n"), "[camera] far 1e38 is out of range"),
        (format!("{sphere}[camera]\northo_half_height = 1e38\n"), "[camera] ortho_half_height 1e38 is out of range"),
        (format!("{sphere}[camera]\nposition = [1e38, 1.0, 1.0]\n"), "[camera] position 1e38 is out of range"),
    ];
    for (text, expected) in cases {
        match parse(&text) {
            Ok(_) => panic!("accepted:\n{text}"),
            Err(e) => assert!(e.to_string().contains(expected), "'{expected}' missing from: {e}\n{text}"),
        }
    }
    // At the ends of the ranges: read.
    let edges = format!("{sphere}position = [999999.0, 0.0, 0.0]\n[[lights]]\nposition = [0.0, 1.0, 0.0]\nradius = 0.000001\ncolor = [10000000.0, 0.0, 0.0]\n");
    parse(&edges).unwrap_or_else(|e| panic!("{e}"));
}

/// A position of 3,000,000 numbers is refused at its fourth, at once.
#[test]
fn a_huge_array_is_refused_at_its_fourth_number() {
    let numbers = vec!["0.5"; 3_000_000].join(", ");
    let text = format!("[[objects]]\nmesh = \"sphere\"\nposition = [{numbers}]\n");
    let start = std::time::Instant::now();
    let e = parse(&text).unwrap_err().to_string();
    assert!(e.contains("line 3: more than 3 numbers"), "{}", &e[..e.len().min(200)]);
    assert!(start.elapsed().as_secs_f32() < 5.0, "{:?}", start.elapsed());
}

#[test]
fn a_features_table_is_read_by_its_feature_and_its_errors_keep_their_lines() {
    use crate::environment::Environment;
    let base = "[[objects]]\nmesh = \"sphere\"\n\n[environment]\n";
    let refused = |body: &str| parse(&format!("{base}{body}")).map(drop).expect_err("refused").to_string();
    assert_eq!(refused("file = \"sky\"\nintensity = \"x\"\n"), "line 6: invalid type: string \"x\", expected f32");
    assert_eq!(refused("file = \"sky\"\nintensity = -1.0\n"), "[environment] intensity -1 must not be negative");
    assert!(refused("file = \"sky\"\nbogus = 1\n").starts_with("line 6: unknown field `bogus`"));
    assert!(refused("file = \"studio.hdr\"\n").contains("no folder"));
    let top = parse("[[objects]]\nmesh = \"sphere\"\n[bogus]\nx = 1\n").map(drop).expect_err("refused").to_string();
    assert!(top.starts_with("line 3: unknown field `bogus`") && top.ends_with("or a feature's table: `environment`"), "{top}");
    let lit = parse(&format!("{base}file = \"sky\"\nintensity = 2.0\nrotation_deg = 90.0\n")).expect("a sky").scene;
    let env = lit.sections.get::<Environment>().expect("the file's sky");
    assert_eq!((env.intensity, env.rotation, env.background), (2.0, 90f32.to_radians(), false));
    assert!(parse(&format!("{base}file = \"none\"\n")).expect("none").scene.sections.get::<Environment>().is_none());
}
