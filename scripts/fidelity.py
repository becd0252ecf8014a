"""The fidelity harness: scenes rendered by manylights and by an independent path tracer
(Mitsuba 3, from PyPI) with the same camera, environment, lights and materials, scored per
scene. Run through scripts/fidelity.sh, which installs what it needs.

Score (docs/DESIGN.md#how-close-to-a-path-tracer): both images in the display's encoding
(the pbr model's ACES curve, then gamma 1/2.2, 8 bits: the path tracer's linear image goes
through manylights' own curve), over the pixels the path tracer finds a surface at; per pixel
the perceptual YIQ difference of 8-bit colours (Kotsarenko and Ramos' weights, as pixelmatch
uses them: 0 equal, 35215 black against white); the score is 20·log10 of the root of its
mean over 35215 — in dB, lower is closer (−20 dB: a tenth of the black-to-white distance).

The path tracer renders direct light only (max_depth 2: what manylights computes — it has no
indirect light) and, beside it, every bounce (max_depth 8); scenes put objects apart so that
one hides little of the environment from another (manylights' environment light is not
shadowed by the scene). Point lights are left out: a radius-limited light's falloff has no
counterpart in a path tracer; directional lights have none and are in.
"""

import json
import math
import os
import subprocess
import sys
from pathlib import Path

import numpy as np
from PIL import Image

WIDTH, HEIGHT = 240, 180
SPP = 256


# ---------------------------------------------------------------- environments


def write_hdr(path, texels):
    """An equirectangular image (rows top to bottom, float RGB) as a Radiance .hdr file."""
    h, w, _ = texels.shape
    m = texels.max(-1)
    e = np.where(m > 1e-32, np.ceil(np.log2(np.maximum(m, 1e-32))), -128).astype(np.int32)
    scale = np.ldexp(1.0, 8 - e)
    rgb = np.clip(texels * scale[..., None], 0, 255).astype(np.uint8)
    exponent = np.where(m > 1e-32, np.clip(e + 128, 0, 255), 0).astype(np.uint8)
    with open(path, "wb") as f:
        f.write(b"#?RADIANCE\nFORMAT=32-bit_rle_rgbe\n\n-Y %d +X %d\n" % (h, w))
        f.write(np.concatenate([rgb, exponent[..., None]], -1).tobytes())


def directions(w, h):
    """Each texel's direction: u turns about +Y (u = 0.5 looks along -Z), v = 0 looks up."""
    u = (np.arange(w) + 0.5) / w
    v = (np.arange(h) + 0.5) / h
    theta, phi = np.meshgrid(v * math.pi, (u - 0.5) * 2 * math.pi, indexing="ij")
    return np.stack([np.sin(theta) * np.sin(phi), np.cos(theta), -np.sin(theta) * np.cos(phi)], -1)


def studio(w=512):
    """A studio: dim grey walls, a warm key softbox, a cool fill, a bright strip overhead."""
    d = directions(w, w // 2)
    radiance = np.full(d.shape, 0.25) * (0.6 + 0.4 * np.clip(d[..., 1:2] + 0.5, 0, 1))

    def softbox(towards, size, colour):
        t = np.array(towards, float)
        t /= np.linalg.norm(t)
        c = (d * t).sum(-1)
        return np.where(c > math.cos(size), 1.0, 0.0)[..., None] * np.array(colour)

    radiance += softbox([-0.6, 0.5, 0.6], 0.35, [6.0, 5.0, 4.0])
    radiance += softbox([0.8, 0.2, 0.4], 0.45, [1.0, 1.3, 1.8])
    radiance += softbox([0.0, 1.0, -0.2], 0.25, [3.0, 3.0, 3.0])
    return radiance


def gradient_sky(w=512):
    """A blue sky over a bright horizon and a dark ground, smooth everywhere."""
    d = directions(w, w // 2)
    up = np.clip(d[..., 1:2], 0, 1)
    sky = np.array([0.95, 0.97, 1.0]) * (1 - np.sqrt(up)) + np.array([0.18, 0.36, 0.85]) * np.sqrt(up)
    ground = np.array([0.16, 0.14, 0.12])
    t = np.clip((d[..., 1:2] + 0.04) / 0.08, 0, 1)
    t = t * t * (3 - 2 * t)
    return ground * (1 - t) + sky * t


# ---------------------------------------------------------------- scenes


def sphere_grid():
    """Spheres in two rows, dielectric above and metal below, roughness 0.1 to 1 along them."""
    objects = []
    for row, metallic in enumerate([0.0, 1.0]):
        for col, roughness in enumerate([0.1, 0.3, 0.5, 0.75, 1.0]):
            colour = [0.9, 0.5, 0.2] if metallic == 0.0 else [0.95, 0.85, 0.6]
            objects.append(
                {"position": [(col - 2) * 3.5, 1.75 - row * 3.5, 0.0], "scale": 1.0, "albedo": colour, "roughness": roughness, "metallic": metallic}
            )
    return objects


def scenes():
    """(name, environment file maker, objects, camera (eye, target, fov_y), directional lights)."""
    grid = sphere_grid()
    wide = ([0.0, 0.0, 19.0], [0.0, 0.0, 0.0], 45.0)
    one = [{"position": [0.0, 0.0, 0.0], "scale": 1.0, "albedo": [0.8, 0.8, 0.8], "roughness": 0.4, "metallic": 0.0}]
    close = ([0.0, 0.6, 3.6], [0.0, 0.0, 0.0], 40.0)
    sun = [{"direction": [0.5, -0.8, -0.4], "color": [2.0, 1.9, 1.7]}]
    return [
        ("spheres-studio", studio, grid, wide, []),
        ("spheres-sky", gradient_sky, grid, wide, []),
        ("sphere-sky-and-sun", gradient_sky, one, close, sun),
        ("metal-sphere-studio", studio, [dict(one[0], albedo=[0.95, 0.64, 0.54], roughness=0.25, metallic=1.0)], close, []),
    ]


def manylights_scene(path, env_file, objects, camera, directional):
    """The scene file manylights renders: the objects, a light too small to reach them (a file
    without lights would get the default rig), the directional lights, the environment."""
    eye, target, fov = camera
    lines = [
        "[camera]",
        f"position = {eye}",
        f"target = {target}",
        f"fov_y_deg = {fov}",
        "near = 0.1",
        "far = 100.0",
        "[shading]",
        'model = "pbr"',
        "ambient = 0.0",
        "[environment]",
        f'file = "{env_file.name}"',
        "[[lights]]",
        "position = [90.0, 90.0, 90.0]",
        "radius = 0.001",
    ]
    for d in directional:
        lines += ["[[lights]]", 'kind = "directional"', f"direction = {d['direction']}", f"color = {d['color']}"]
    for o in objects:
        material = f"{{ albedo = {o['albedo']}, roughness = {o['roughness']}, metallic = {o['metallic']} }}"
        lines += ["[[objects]]", 'mesh = "sphere"', f"position = {o['position']}", f"scale = {o['scale']}", f"material = {material}"]
    path.write_text("\n".join(lines) + "\n")


def mitsuba_render(env_file, objects, camera, directional, depth):
    """The path tracer's linear image (RGB) and where it found a surface (alpha)."""
    import mitsuba as mi

    mi.set_variant("scalar_rgb")
    eye, target, fov = camera
    scene = {
        "type": "scene",
        "integrator": {"type": "path", "max_depth": depth, "hide_emitters": True},
        "sensor": {
            "type": "perspective",
            "fov": fov,
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f.look_at(origin=eye, target=target, up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": WIDTH, "height": HEIGHT, "pixel_format": "rgba", "rfilter": {"type": "box"}},
            "sampler": {"type": "stratified", "sample_count": SPP},
        },
        "environment": {"type": "envmap", "filename": str(env_file), "to_world": mi.ScalarTransform4f.rotate([0, 1, 0], ENVMAP_TURN_DEG)},
    }
    for i, d in enumerate(directional):
        scene[f"sun{i}"] = {"type": "directional", "direction": d["direction"], "irradiance": {"type": "rgb", "value": d["color"]}}
    for i, o in enumerate(objects):
        scene[f"sphere{i}"] = {
            "type": "sphere",
            "center": o["position"],
            "radius": o["scale"],
            "bsdf": {
                "type": "principled",
                "base_color": {"type": "rgb", "value": o["albedo"]},
                "roughness": o["roughness"],
                "metallic": o["metallic"],
                "specular": 0.5,
            },
        }
    image = np.array(mi.render(mi.load_dict(scene)))
    return image[..., :3], image[..., 3]


# Mitsuba's envmap reads u = atan2(x, −z)/2π without manylights' half-turn: it is turned by
# half a turn about +Y so that both see one environment the same way round.
ENVMAP_TURN_DEG = 180.0


# ---------------------------------------------------------------- the score


def display(linear):
    """manylights' pbr output encoding: ACES (Narkowicz's fit), gamma 1/2.2, 8 bits."""
    x = np.maximum(linear, 0)
    aces = np.clip(x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14), 0, 1)
    return np.clip(np.round(aces ** (1 / 2.2) * 255), 0, 255)


def yiq_delta(a, b):
    """pixelmatch's perceptual colour difference of 8-bit RGB images (0 to 35215)."""

    def yiq(c):
        r, g, b = c[..., 0], c[..., 1], c[..., 2]
        return (
            r * 0.29889531 + g * 0.58662247 + b * 0.11448223,
            r * 0.59597799 - g * 0.27417610 - b * 0.32180189,
            r * 0.21147017 - g * 0.52261711 + b * 0.31114694,
        )

    (ya, ia, qa), (yb, ib, qb) = yiq(a.astype(float)), yiq(b.astype(float))
    return 0.5053 * (ya - yb) ** 2 + 0.299 * (ia - ib) ** 2 + 0.1957 * (qa - qb) ** 2


def score(ours, theirs, mask):
    mean = yiq_delta(ours, theirs)[mask].mean()
    return 20 * math.log10(max(math.sqrt(mean / 35215.0), 1e-6))


# ---------------------------------------------------------------- main


def main():
    binary, out = Path(sys.argv[1]), Path(sys.argv[2])
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for name, make_env, objects, camera, directional in scenes():
        env_file = out / f"{make_env.__name__}.hdr"
        if not env_file.exists():
            write_hdr(env_file, make_env().astype(np.float32))
        scene_file = out / f"{name}.toml"
        manylights_scene(scene_file, env_file, objects, camera, directional)
        ours_png = out / f"{name}-manylights.png"
        run = subprocess.run(
            [str(binary), "render", "--scene", str(scene_file), "--exposure", "0", "--supersample", "4",
             "--width", str(WIDTH), "--height", str(HEIGHT), "--out", str(ours_png)],
            capture_output=True, text=True,
        )
        if run.returncode != 0:
            sys.exit(f"manylights failed on {name}: {run.stderr.strip()}")
        ours = np.array(Image.open(ours_png).convert("RGB")).astype(float)
        result = {"scene": name}
        pictures = [ours]
        for label, depth in [("direct", 2), ("every bounce", 8)]:
            linear, alpha = mitsuba_render(env_file, objects, camera, directional, depth)
            theirs = display(linear)
            mask = alpha > 0.5
            result[label] = score(ours, theirs, mask)
            pictures.append(np.where(mask[..., None], theirs, ours))
        Image.fromarray(np.concatenate(pictures, 1).astype(np.uint8)).save(out / f"{name}-side-by-side.png")
        rows.append(result)
        print(f"{name:24} {result['direct']:7.1f} dB direct light   {result['every bounce']:7.1f} dB every bounce", flush=True)
    (out / "fidelity.json").write_text(json.dumps(rows, indent=1))
    worst = max(r["direct"] for r in rows)
    print(f"worst scene: {worst:.1f} dB against the path tracer's direct light (pictures: manylights | direct | every bounce in {out})")


if __name__ == "__main__":
    main()
