"""The fidelity harness: scenes rendered by manylights and by an independent path tracer
(Mitsuba 3, from PyPI) with the same camera, environment, lights and materials, scored per
scene. Run through scripts/fidelity.sh, which installs what it needs.

Score (docs/DESIGN.md#how-close-to-a-path-tracer): both images in the display's encoding
(the pbr model's ACES curve, then gamma 1/2.2, 8 bits: the path tracer's linear image goes
through manylights' own curve), over the pixels the path tracer finds a surface at; per pixel
the perceptual YIQ difference of 8-bit colours (Kotsarenko and Ramos' weights, as pixelmatch
uses them: 0 equal, 35215 black against white); the score is 20·log10 of the root of its
mean over 35215 — in dB, lower is closer (−20 dB: a tenth of the black-to-white distance).

The path tracer renders direct light only (what manylights computes — it has no indirect
light; paths go on through thin glass) and, beside it, every bounce (8 vertices); scenes lit by
an environment put objects apart so that one hides little of it from another (manylights'
environment light is not shadowed by the scene). manylights' point and spot lights, whose
(1 − d/r)² falloff no emitter of Mitsuba's has, are summed by the path tracer's integrator
itself (fidelity_mitsuba.py), with shadow rays; manylights shadows them (and directional
lights) by rays too. Every opaque material, textured or not, with clear coat and sheen, is
glTF's own as its specification writes it (fidelity_mitsuba.GltfBSDF: Lambert diffuse, where
Mitsuba's principled BSDF is Disney's); thin transmitting glass Mitsuba's thin dielectric.
"""

import io
import json
import math
import struct
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


def material(albedo, roughness, metallic, **lobes):
    """A material: base colour, roughness, metallic and glTF extensions' factors:
    clearcoat=(factor, roughness), sheen=(colour, roughness), transmission=factor; textures=
    {"baseColor": sRGB texels, "metallicRoughness": texels (roughness in green, metallic in
    blue)}, each multiplying its factors."""
    return dict(albedo=albedo, roughness=roughness, metallic=metallic, **lobes)


def sphere_grid():
    """Spheres in two rows, dielectric above and metal below, roughness 0.1 to 1 along them."""
    objects = []
    for row, metallic in enumerate([0.0, 1.0]):
        for col, roughness in enumerate([0.1, 0.3, 0.5, 0.75, 1.0]):
            colour = [0.9, 0.5, 0.2] if metallic == 0.0 else [0.95, 0.85, 0.6]
            objects.append(
                {"shape": "sphere", "position": [(col - 2) * 3.5, 1.75 - row * 3.5, 0.0], "scale": 1.0, "material": material(colour, roughness, metallic)}
            )
    return objects


def lobe_row(lobes):
    """Three spheres of one rough red base side by side, each with the extension's factors
    at another setting."""
    return [
        {"shape": "sphere", "position": [(i - 1) * 2.6, 0.0, 0.0], "scale": 1.0, "material": material([0.7, 0.12, 0.08], 0.6, 0.0, **extra)}
        for i, extra in enumerate(lobes)
    ]


def floor_and_spots():
    """Spheres on a floor under spot, point and directional lights, no environment: the
    lights' falloff, cones and shadows."""
    objects = [{"shape": "floor", "position": [0.0, -1.0, 0.0], "scale": 8.0, "material": material([0.6, 0.6, 0.6], 0.7, 0.0)}]
    for i, (colour, roughness, metallic) in enumerate([([0.9, 0.3, 0.2], 0.4, 0.0), ([0.95, 0.9, 0.8], 0.3, 1.0), ([0.2, 0.5, 0.9], 0.8, 0.0)]):
        objects.append({"shape": "sphere", "position": [(i - 1) * 2.8, 0.0, 0.0], "scale": 1.0, "material": material(colour, roughness, metallic)})
    lights = [
        {"position": [-2.8, 4.0, 2.0], "direction": [0.0, -1.0, -0.4], "inner_deg": 15.0, "outer_deg": 35.0, "radius": 9.0, "color": [6.0, 5.0, 3.5]},
        {"position": [3.0, 3.5, 2.5], "direction": [-0.3, -1.0, -0.6], "inner_deg": 5.0, "outer_deg": 25.0, "radius": 8.0, "color": [2.5, 4.0, 6.0]},
        {"position": [0.0, 1.8, 2.2], "radius": 4.0, "color": [3.0, 2.0, 1.5]},
        {"position": [1.4, -0.4, -1.5], "radius": 3.0, "color": [1.0, 3.0, 1.2]},
    ]
    return objects, lights


def many_lights(count=1000, seed=7):
    """`count` point lights about the sphere grid: each 0.8 to 2 wide, of a random hue."""
    rng = np.random.default_rng(seed)
    lights = []
    for _ in range(count):
        p = rng.uniform([-9.5, -4.0, -2.5], [9.5, 4.0, 2.5])
        hue = rng.uniform(0, 2 * math.pi)
        colour = 0.5 + 0.5 * np.cos(hue + np.array([0.0, 2.0, 4.0]))
        lights.append({"position": p.round(4).tolist(), "radius": round(float(rng.uniform(0.8, 2.0)), 3), "color": (colour * 1.5).round(4).tolist()})
    return lights


def tinted_glass():
    """A pane of tinted glass (thin, transmission 1) in front of three spheres, the
    environment shown behind."""
    spheres = [{"shape": "sphere", "position": [(i - 1) * 2.6, 0.0, -1.5], "scale": 1.0, "material": material(c, 0.35, 0.0)}
               for i, c in enumerate([[0.9, 0.3, 0.2], [0.9, 0.9, 0.85], [0.2, 0.5, 0.9]])]
    pane = {"shape": "pane", "position": [0.0, 0.0, 1.0], "scale": 1.6, "material": material([0.95, 0.75, 0.35], 0.05, 0.0, transmission=1.0)}
    return spheres + [pane]


def textured_spheres():
    """Three spheres textured as glTF textures them: a base colour checker, and roughness
    (green) and metallic (blue) in stripes and bands."""
    u, v = np.meshgrid(np.arange(256) / 256, np.arange(128) / 128)
    checker = ((u * 16).astype(int) + (v * 8).astype(int)) % 2 == 0
    base = np.where(checker[..., None], [220, 140, 64], [50, 115, 205])
    metal_rough = np.stack([np.zeros_like(u), np.where((u * 12).astype(int) % 2 == 0, 0.25, 0.8), (v > 0.5) * 1.0], -1) * 255
    textures = {"baseColor": base, "metallicRoughness": metal_rough.round()}
    return [
        {"shape": "sphere", "position": [(i - 1) * 2.6, 0.0, 0.0], "scale": 1.0, "material": material([1.0, 1.0, 1.0], 1.0, 1.0, textures=textures)}
        for i in range(3)
    ]


# A Khronos glTF sample model: DamagedHelmet (CC BY 4.0, theblueturtle_; see the README beside
# it), as three.js's glTF exporter writes it: one material with every metallic-roughness
# texture.
HELMET = Path(__file__).parent / "fidelity" / "DamagedHelmet.glb"


def scenes():
    """Each scene: name, environment maker (None: no environment), objects, camera (eye, target,
    fov_y), directional lights, point and spot lights, whether the environment is the
    background."""
    grid = sphere_grid()
    wide = ([0.0, 0.0, 19.0], [0.0, 0.0, 0.0], 45.0)
    one = [{"shape": "sphere", "position": [0.0, 0.0, 0.0], "scale": 1.0, "material": material([0.8, 0.8, 0.8], 0.4, 0.0)}]
    close = ([0.0, 0.6, 3.6], [0.0, 0.0, 0.0], 40.0)
    row = ([0.0, 0.8, 7.5], [0.0, 0.0, 0.0], 40.0)
    sun = [{"direction": [0.5, -0.8, -0.4], "color": [2.0, 1.9, 1.7]}]
    metal = [dict(one[0], material=material([0.95, 0.64, 0.54], 0.25, 1.0))]
    floor, spots = floor_and_spots()
    helmet = [{"shape": "model", "file": HELMET, "position": [0.0, 0.0, 0.0], "scale": 1.0}]
    helmet_view = ([0.6, 0.4, 3.4], [0.0, 0.0, 0.0], 40.0)
    return [
        dict(name="spheres-studio", env=studio, objects=grid, camera=wide),
        dict(name="spheres-sky", env=gradient_sky, objects=grid, camera=wide),
        dict(name="sphere-sky-and-sun", env=gradient_sky, objects=one, camera=close, directional=sun),
        dict(name="metal-sphere-studio", env=studio, objects=metal, camera=close),
        dict(name="clearcoat-studio", env=studio, objects=lobe_row([dict(clearcoat=(1.0, 0.05)), dict(clearcoat=(1.0, 0.3)), dict(clearcoat=(0.5, 0.1))]), camera=row),
        dict(name="sheen-studio", env=studio, objects=lobe_row([dict(sheen=([0.9, 0.7, 1.0], 0.3)), dict(sheen=([1.0, 1.0, 1.0], 0.6)), dict(sheen=([0.4, 0.9, 0.5], 0.9))]), camera=row),
        dict(name="textured-spheres-sky", env=gradient_sky, objects=textured_spheres(), camera=row),
        dict(name="damaged-helmet-studio", env=studio, objects=helmet, camera=helmet_view),
        dict(name="damaged-helmet-sky", env=gradient_sky, objects=helmet, camera=helmet_view),
        dict(name="glass-studio", env=studio, objects=tinted_glass(), camera=row, background=True),
        dict(name="spots-points-sun", env=None, objects=floor, camera=([0.0, 3.0, 8.5], [0.0, -0.3, 0.0], 45.0), directional=[dict(sun[0], color=[0.5, 0.5, 0.55])], lights=spots),
        dict(name="sky-and-1000-lights", env=gradient_sky, objects=grid, camera=wide, lights=many_lights()),
    ]


# ---------------------------------------------------------------- meshes (glTF for manylights)


def uv_sphere(rings=64, segments=128):
    """A unit sphere: positions (= normals), texture coordinates (u round +Y from +Z, v from
    the top down, as glTF's images are) and triangles."""
    theta = np.linspace(0, math.pi, rings + 1)
    phi = np.linspace(0, 2 * math.pi, segments + 1)
    t, p = np.meshgrid(theta, phi, indexing="ij")
    pos = np.stack([np.sin(t) * np.sin(p), np.cos(t), np.sin(t) * np.cos(p)], -1).reshape(-1, 3).astype(np.float32)
    uv = np.stack([p / (2 * math.pi), t / math.pi], -1).reshape(-1, 2).astype(np.float32)
    idx = []
    for r in range(rings):
        for c in range(segments):
            a, b = r * (segments + 1) + c, (r + 1) * (segments + 1) + c
            idx += [a, b, a + 1, a + 1, b, b + 1]
    return {"pos": pos, "nrm": pos, "uv": uv, "idx": np.array(idx, np.uint32)}


def pane():
    """A unit square in the xy plane facing +z."""
    pos = np.array([[-1, -1, 0], [1, -1, 0], [1, 1, 0], [-1, 1, 0]], np.float32)
    uv = np.array([[0, 1], [1, 1], [1, 0], [0, 0]], np.float32)
    return {"pos": pos, "nrm": np.tile(np.array([[0, 0, 1]], np.float32), (4, 1)), "uv": uv, "idx": np.array([0, 1, 2, 0, 2, 3], np.uint32)}


def png_bytes(texels):
    """8-bit RGB texels (rows top to bottom) as PNG bytes."""
    buffer = io.BytesIO()
    Image.fromarray(texels.astype(np.uint8)).save(buffer, "PNG")
    return buffer.getvalue()


def write_glb(path, mesh, m):
    """One mesh with one material (`m`: its factors, extensions and textures) as a binary
    glTF, its textures' PNGs inside."""
    parts = [(mesh["pos"], 34962), (mesh["nrm"], 34962), (mesh["uv"], 34962), (mesh["idx"], 34963)]
    textures = m.get("textures", {})
    images = [png_bytes(t) for t in textures.values()]
    blob, views = b"", []
    for data in [a.tobytes() for a, _ in parts] + images:
        views.append({"buffer": 0, "byteOffset": len(blob), "byteLength": len(data)})
        blob += data + b"\0" * (-len(data) % 4)
    for view, (_, target) in zip(views, parts):
        view["target"] = target
    extensions = {}
    if "clearcoat" in m:
        extensions["KHR_materials_clearcoat"] = {"clearcoatFactor": m["clearcoat"][0], "clearcoatRoughnessFactor": m["clearcoat"][1]}
    if "sheen" in m:
        extensions["KHR_materials_sheen"] = {"sheenColorFactor": m["sheen"][0], "sheenRoughnessFactor": m["sheen"][1]}
    if "transmission" in m:
        extensions["KHR_materials_transmission"] = {"transmissionFactor": m["transmission"]}
    pbr = {"baseColorFactor": m["albedo"] + [1.0], "roughnessFactor": m["roughness"], "metallicFactor": m["metallic"]}
    for i, name in enumerate(textures):
        pbr[f"{name}Texture"] = {"index": i}
    pos = mesh["pos"]
    doc = {
        "asset": {"version": "2.0"},
        "extensionsUsed": sorted(extensions),
        "scene": 0,
        "scenes": [{"nodes": [0]}],
        "nodes": [{"mesh": 0}],
        "meshes": [{"primitives": [{"attributes": {"POSITION": 0, "NORMAL": 1, "TEXCOORD_0": 2}, "indices": 3, "material": 0}]}],
        "materials": [{"pbrMetallicRoughness": pbr, "extensions": extensions}],
        "buffers": [{"byteLength": len(blob)}],
        "bufferViews": views,
        "accessors": [
            {"bufferView": 0, "componentType": 5126, "count": len(pos), "type": "VEC3", "min": pos.min(0).tolist(), "max": pos.max(0).tolist()},
            {"bufferView": 1, "componentType": 5126, "count": len(pos), "type": "VEC3"},
            {"bufferView": 2, "componentType": 5126, "count": len(pos), "type": "VEC2"},
            {"bufferView": 3, "componentType": 5125, "count": len(mesh["idx"]), "type": "SCALAR"},
        ],
    }
    if images:
        doc["images"] = [{"bufferView": 4 + i, "mimeType": "image/png"} for i in range(len(images))]
        doc["samplers"] = [{"magFilter": 9729, "minFilter": 9987}]
        doc["textures"] = [{"source": i, "sampler": 0} for i in range(len(images))]
    text = json.dumps(doc).encode()
    text += b" " * (-len(text) % 4)
    chunks = struct.pack("<II", len(text), 0x4E4F534A) + text + struct.pack("<II", len(blob), 0x004E4942) + blob
    path.write_bytes(struct.pack("<III", 0x46546C67, 2, 12 + len(chunks)) + chunks)


def write_ply(path, mesh):
    """The mesh as a binary PLY file (positions, normals, texture coordinates) for the path
    tracer."""
    pos, nrm, uv, idx = mesh["pos"], mesh["nrm"], mesh["uv"], mesh["idx"].reshape(-1, 3)
    header = (
        "ply\nformat binary_little_endian 1.0\n"
        f"element vertex {len(pos)}\n" + "".join(f"property float {c}\n" for c in ("x", "y", "z", "nx", "ny", "nz", "u", "v"))
        + f"element face {len(idx)}\nproperty list uchar int vertex_indices\nend_header\n"
    )
    vertices = np.concatenate([pos, nrm, uv], 1).astype("<f4")
    faces = np.zeros(len(idx), dtype=[("n", "u1"), ("i", "<i4", 3)])
    faces["n"], faces["i"] = 3, idx
    path.write_bytes(header.encode() + vertices.tobytes() + faces.tobytes())


def read_glb(path):
    """A binary glTF of one material as the path tracer needs it: every drawn triangle in world
    space (positions, normals, TEXCOORD_0 as one mesh) and the material's factors and images
    (bytes, by texture name)."""
    data = path.read_bytes()
    json_length = struct.unpack_from("<I", data, 12)[0]
    doc = json.loads(data[20 : 20 + json_length])
    blob = data[20 + json_length + 8 :]
    kinds = {5120: "i1", 5121: "u1", 5122: "<i2", 5123: "<u2", 5125: "<u4", 5126: "<f4"}
    widths = {"SCALAR": 1, "VEC2": 2, "VEC3": 3, "VEC4": 4}

    def accessor(i):
        a = doc["accessors"][i]
        view = doc["bufferViews"][a["bufferView"]]
        kind, width = np.dtype(kinds[a["componentType"]]), widths[a["type"]]
        stride = view.get("byteStride", kind.itemsize * width)
        start = view.get("byteOffset", 0) + a.get("byteOffset", 0)
        rows = np.lib.stride_tricks.as_strided(
            np.frombuffer(blob, kind, offset=start, count=(a["count"] - 1) * stride // kind.itemsize + width),
            (a["count"], width), (stride, kind.itemsize))
        return np.array(rows, np.float64 if kind.kind == "f" else np.int64)

    if len(doc["materials"]) != 1:
        sys.exit(f"{path}: the harness reads models of one material")
    pos, nrm, uv, idx = [], [], [], []

    def walk(node, parent):
        n = doc["nodes"][node]
        local = np.array(n["matrix"], float).reshape(4, 4).T if "matrix" in n else np.eye(4)
        world = parent @ local
        for prim in doc["meshes"][n["mesh"]]["primitives"] if "mesh" in n else []:
            at = prim["attributes"]
            p = accessor(at["POSITION"])
            base = sum(len(x) for x in pos)
            pos.append(p @ world[:3, :3].T + world[:3, 3])
            nrm.append(accessor(at["NORMAL"]) @ np.linalg.inv(world[:3, :3]))
            uv.append(accessor(at["TEXCOORD_0"]))
            idx.append(accessor(prim["indices"]).ravel() + base)
        for child in n.get("children", []):
            walk(child, world)

    for root in doc["scenes"][doc.get("scene", 0)]["nodes"]:
        walk(root, np.eye(4))
    nrm = np.concatenate(nrm)
    nrm /= np.linalg.norm(nrm, axis=1, keepdims=True)
    mesh = {"pos": np.concatenate(pos).astype(np.float32), "nrm": nrm.astype(np.float32), "uv": np.concatenate(uv).astype(np.float32),
            "idx": np.concatenate(idx).astype(np.uint32)}
    m = doc["materials"][0]
    pbr = m.get("pbrMetallicRoughness", {})

    def image(ref):
        view = doc["bufferViews"][doc["images"][doc["textures"][ref["index"]]["source"]]["bufferView"]]
        return blob[view.get("byteOffset", 0) : view.get("byteOffset", 0) + view["byteLength"]]

    images = {name: image(ref) for name, ref in [("baseColor", pbr.get("baseColorTexture")), ("metallicRoughness", pbr.get("metallicRoughnessTexture")),
                                                  ("normal", m.get("normalTexture")), ("emissive", m.get("emissiveTexture"))] if ref}
    factors = {"baseColor": pbr.get("baseColorFactor", [1, 1, 1, 1])[:3], "roughness": pbr.get("roughnessFactor", 1.0),
               "metallic": pbr.get("metallicFactor", 1.0), "emissive": m.get("emissiveFactor", [0, 0, 0])}
    return mesh, images, factors


def model_shape(path, out, name):
    """The path tracer's shape for the glTF model at `path`: its triangles (a PLY file), its
    material (glTF's on its textures, under its normal map: mitsuba_bsdf, plugin `name`) and
    its emission. Images go through PIL into files of `out`: roughness and metallic as grey
    images of their channels; the normal map's green channel turned over (glTF's texture
    coordinates run down the image, so its +y is towards −v; Mitsuba's frame takes +y along
    +v)."""
    mesh, images, factors = read_glb(path)
    ply = out / f"{path.stem}.ply"
    write_ply(ply, mesh)
    files = {}
    for role, data in images.items():
        texels = np.array(Image.open(io.BytesIO(data)).convert("RGB"))
        if role == "metallicRoughness":
            for channel, grey in [(1, "roughness"), (2, "metallic")]:
                files[grey] = out / f"{path.stem}-{grey}.png"
                Image.fromarray(texels[..., channel]).save(files[grey])
            continue
        if role == "normal":
            texels[..., 1] = 255 - texels[..., 1]
        files[role] = out / f"{path.stem}-{role}.png"
        Image.fromarray(texels).save(files[role])

    def texture(role, factor, raw):
        bitmap = {"type": "bitmap", "filename": str(files[role]), "raw": raw}
        return bitmap if np.allclose(factor, 1.0) else {"type": "scale", "scale": factor, "texture": bitmap} if np.isscalar(factor) else sys.exit("a coloured factor over a texture")

    m = material(factors["baseColor"], factors["roughness"], factors["metallic"])
    m["maps"] = {role: files[role] for role in ("baseColor", "roughness", "metallic") if role in files}
    bsdf = mitsuba_bsdf(m, name)
    if "normal" in files:
        bsdf = {"type": "normalmap", "normalmap": {"type": "bitmap", "filename": str(files["normal"]), "raw": True}, "bsdf": bsdf}
    shape = {"type": "ply", "filename": str(ply), "bsdf": bsdf}
    if "emissive" in files:
        shape["emitter"] = {"type": "area", "radiance": texture("emissive", factors["emissive"], False)}
    elif max(factors["emissive"]) > 0:
        shape["emitter"] = {"type": "area", "radiance": {"type": "rgb", "value": factors["emissive"]}}
    return shape


def extended(m):
    """Whether `m` needs a glTF file of its own in manylights (extensions or textures)."""
    return any(k in m for k in ("clearcoat", "sheen", "transmission", "textures"))


# ---------------------------------------------------------------- the two renderers' scenes


def manylights_scene(path, scene, env_file):
    """The scene file manylights renders: the objects (a glTF file of their own where their
    material has extensions), the lights (a light too small to reach anything where there are
    none: a file without lights would get the default rig), the environment."""
    eye, target, fov = scene["camera"]
    lines = ["[camera]", f"position = {eye}", f"target = {target}", f"fov_y_deg = {fov}", "near = 0.1", "far = 100.0",
             "[shading]", 'model = "pbr"', "ambient = 0.0"]
    if env_file:
        lines += ["[environment]", f'file = "{env_file.name}"'] + (["background = true"] if scene.get("background") else [])
    point_lights = scene.get("lights", [])
    for l in point_lights or [{"position": [90.0, 90.0, 90.0], "radius": 0.001, "color": [1.0, 1.0, 1.0]}]:
        lines += ["[[lights]]", f"position = {l['position']}", f"radius = {l['radius']}", f"color = {l['color']}"]
        if "inner_deg" in l:
            lines += ['kind = "spot"', f"direction = {l['direction']}", f"inner_deg = {l['inner_deg']}", f"outer_deg = {l['outer_deg']}"]
    for d in scene.get("directional", []):
        lines += ["[[lights]]", 'kind = "directional"', f"direction = {d['direction']}", f"color = {d['color']}"]
    for i, o in enumerate(scene["objects"]):
        place = [f"position = {o['position']}", f"scale = {o['scale']}"]
        if o["shape"] == "model":
            copy = path.with_name(o["file"].name)
            copy.write_bytes(o["file"].read_bytes())
            lines += ["[[objects]]", f'gltf = "{copy.name}"', *place]
            continue
        m = o["material"]
        # Plain spheres and the floor are manylights' own meshes (sphere, plane).
        built_in = {"sphere": "sphere", "floor": "plane"}.get(o["shape"])
        if built_in and not extended(m):
            inline = f"{{ albedo = {m['albedo']}, roughness = {m['roughness']}, metallic = {m['metallic']} }}"
            lines += ["[[objects]]", f'mesh = "{built_in}"', *place, f"material = {inline}"]
        else:
            glb = path.with_name(f"{path.stem}-{i}.glb")
            write_glb(glb, uv_sphere() if o["shape"] == "sphere" else pane(), m)
            lines += ["[[objects]]", f'gltf = "{glb.name}"', *place]
    path.write_text("\n".join(lines) + "\n")


def mitsuba_bsdf(m, name):
    """The path tracer's material for `m`: thin glass Mitsuba's thin dielectric, the others
    glTF's material (fidelity_mitsuba.GltfBSDF, a plugin of its own named `name`: its factors
    are the plugin's constants; textures from m["maps"])."""
    import mitsuba as mi
    import fidelity_mitsuba as fm

    if "transmission" in m:
        return {"type": "thindielectric", "int_ior": 1.5, "ext_ior": 1.0, "specular_transmittance": {"type": "rgb", "value": m["albedo"]}}
    mi.register_bsdf(name, lambda props: fm.GltfBSDF(props, m))
    return {"type": name}


def texture_files(m, out):
    """The path tracer's images of `m`'s textures (base colour as is, roughness and metallic
    as grey images of their channels), written into `out` once, named in m["maps"]."""
    if "maps" not in m:
        files = {"baseColor": out / "base_color.png", "roughness": out / "roughness.png", "metallic": out / "metallic.png"}
        Image.fromarray(m["textures"]["baseColor"].astype(np.uint8)).save(files["baseColor"])
        for name, channel in [("roughness", 1), ("metallic", 2)]:
            Image.fromarray(m["textures"]["metallicRoughness"][..., channel].astype(np.uint8)).save(files[name])
        m["maps"] = files


def mitsuba_render(scene, env_file, direct, out):
    """The path tracer's linear image (RGB) and where it found a surface (alpha); its files
    (textures, meshes) written into `out`."""
    import mitsuba as mi
    import fidelity_mitsuba as fm

    eye, target, fov = scene["camera"]
    mi.register_integrator("radius_limited_path", lambda props: fm.RadiusLimitedPath(props, scene.get("lights", []), direct))
    desc = {
        "type": "scene",
        "integrator": {"type": "radius_limited_path", "max_depth": 8},
        "sensor": {
            "type": "perspective",
            "fov": fov,
            "fov_axis": "y",
            "to_world": mi.ScalarTransform4f().look_at(origin=eye, target=target, up=[0, 1, 0]),
            "film": {"type": "hdrfilm", "width": WIDTH, "height": HEIGHT, "pixel_format": "rgba", "rfilter": {"type": "box"}},
            "sampler": {"type": "stratified", "sample_count": SPP},
        },
    }
    if env_file:
        desc["environment"] = {"type": "envmap", "filename": str(env_file), "to_world": mi.ScalarTransform4f().rotate([0, 1, 0], ENVMAP_TURN_DEG)}
    for i, d in enumerate(scene.get("directional", [])):
        desc[f"sun{i}"] = {"type": "directional", "direction": d["direction"], "irradiance": {"type": "rgb", "value": d["color"]}}
    for i, o in enumerate(scene["objects"]):
        if o["shape"] == "model":
            desc[f"object{i}"] = model_shape(o["file"], out, f"gltf_material_{i}")
            continue
        m = o["material"]
        if "textures" in m:
            texture_files(m, out)
        bsdf = mitsuba_bsdf(m, f"gltf_material_{i}")
        at, s = o["position"], o["scale"]
        if o["shape"] == "sphere" and "textures" in m:
            # Textured: the same triangles and texture coordinates as manylights' glTF.
            ply = out / "textured-sphere.ply"
            write_ply(ply, uv_sphere())
            desc[f"object{i}"] = {"type": "ply", "filename": str(ply), "to_world": mi.ScalarTransform4f().translate(at) @ mi.ScalarTransform4f().scale(s), "bsdf": bsdf}
        elif o["shape"] == "sphere":
            desc[f"object{i}"] = {"type": "sphere", "center": at, "radius": s, "bsdf": bsdf}
        else:
            turn = mi.ScalarTransform4f().rotate([1, 0, 0], -90.0) if o["shape"] == "floor" else mi.ScalarTransform4f()
            desc[f"object{i}"] = {"type": "rectangle", "to_world": mi.ScalarTransform4f().translate(at) @ turn @ mi.ScalarTransform4f().scale(s), "bsdf": bsdf}
    image = np.array(mi.render(mi.load_dict(desc)))
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
    import mitsuba as mi

    mi.set_variant("llvm_ad_rgb")
    binary, out = Path(sys.argv[1]), Path(sys.argv[2])
    only = sys.argv[3:]
    out.mkdir(parents=True, exist_ok=True)
    rows = []
    for scene in scenes():
        name = scene["name"]
        if only and name not in only:
            continue
        env_file = None
        if scene["env"]:
            env_file = out / f"{scene['env'].__name__}.hdr"
            if not env_file.exists():
                write_hdr(env_file, scene["env"]().astype(np.float32))
        scene_file = out / f"{name}.toml"
        manylights_scene(scene_file, scene, env_file)
        ours_png = out / f"{name}-manylights.png"
        # Shadow rays where a light may cast a shadow on another object (the path tracer
        # traces every light's).
        casts = bool(scene.get("lights")) or (bool(scene.get("directional")) and len(scene["objects"]) > 1)
        shadows = ["--omni-shadow", "rays"] if casts else []
        run = subprocess.run(
            [str(binary), "render", "--scene", str(scene_file), "--exposure", "0", "--supersample", "4", *shadows,
             "--width", str(WIDTH), "--height", str(HEIGHT), "--out", str(ours_png)],
            capture_output=True, text=True,
        )
        if run.returncode != 0:
            sys.exit(f"manylights failed on {name}: {run.stderr.strip()}")
        ours = np.array(Image.open(ours_png).convert("RGB")).astype(float)
        result = {"scene": name}
        pictures = [ours]
        for label, direct in [("direct", True), ("every bounce", False)]:
            linear, alpha = mitsuba_render(scene, env_file, direct, out)
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
