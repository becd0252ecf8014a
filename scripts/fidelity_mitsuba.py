"""What the fidelity harness (fidelity.py) adds to Mitsuba 3: an integrator that also sums
manylights' radius-limited point and spot lights, and a BSDF that is glTF's metallic-roughness
material with its clear coat and sheen as the glTF specification writes them. Both run in the
llvm_ad_rgb variant (vectorised: Dr.Jit compiles them once for every sample).

The path tracer is manylights' ground truth, so nothing here is manylights' own code: the
BSDF follows the specification's formulas (Smith GGX height-correlated visibility, Fresnel at
v·h, the sheen's directional albedo integrated here), where manylights approximates (its
split sum, its spherical-harmonic diffuse, its 16×16 sheen table, Schlick-Smith visibility,
Fresnel at n·v): the score measures those approximations.
"""

import math

import drjit as dr
import mitsuba as mi
import numpy as np


class RadiusLimitedPath(mi.SamplingIntegrator):
    """A path tracer (emitter and BSDF sampling with multiple importance; surfaces' emission) that
    at every vertex also sums manylights' point and spot lights, each one: colour × (1 − d/r)² × cone², with a
    shadow ray (manylights' falloff has no 1/d²; no emitter of Mitsuba's has that falloff).

    `direct`: only light that reaches the eye after one non-delta scattering (manylights has
    no indirect light); paths go on through delta lobes (thin glass) to the surface behind.
    Else every bounce up to `max_depth` vertices."""

    def __init__(self, props, lights=(), direct=True):
        super().__init__(props)
        self.max_depth = props.get("max_depth", 8)
        self.direct = direct
        self.count = len(lights)
        column = lambda f: mi.Float([f(l) for l in lights]) if lights else mi.Float(0.0)
        self.position = [column(lambda l, j=j: l["position"][j]) for j in range(3)]
        self.colour = [column(lambda l, j=j: l["color"][j]) for j in range(3)]
        self.axis = [column(lambda l, j=j: unit(l.get("direction", [0.0, 0.0, 1.0]))[j]) for j in range(3)]
        self.radius = column(lambda l: l["radius"])
        self.cone_scale, self.cone_offset = column(lambda l: cone(l)[0]), column(lambda l: cone(l)[1])

    def gather3(self, columns, i, kind):
        return kind(*(dr.gather(mi.Float, c, i) for c in columns))

    @dr.syntax
    def sample(self, scene, sampler, ray_, medium=None, active=True):
        ray = mi.Ray3f(ray_)
        L = mi.Spectrum(0.0)
        beta = mi.Spectrum(1.0)
        depth = mi.UInt32(0)
        active = mi.Bool(active)
        valid = mi.Bool(False)
        last = mi.Bool(False)
        prev_si = dr.zeros(mi.SurfaceInteraction3f)
        prev_pdf = mi.Float(1.0)
        prev_delta = mi.Bool(True)
        ctx = mi.BSDFContext()
        n = mi.UInt32(self.count)
        while active:
            si = scene.ray_intersect(ray, ray_flags=mi.RayFlags.All, coherent=depth == 0)
            valid |= (depth == 0) & si.is_valid()
            # Light given off by what the ray meets: a surface's own (glTF's emission), or the
            # environment where a sampled direction leaves the scene (not where the eye's own
            # rays do: the score is over surfaces).
            if depth == 0:
                L += si.emitter(scene).eval(si, si.is_valid())
            else:
                ds = mi.DirectionSample3f(scene, si, prev_si)
                em_pdf = scene.pdf_emitter_direction(prev_si, ds, ~prev_delta)
                mis = dr.select(prev_delta, 1.0, prev_pdf / dr.maximum(prev_pdf + em_pdf, 1e-30))
                L += beta * mis * ds.emitter.eval(si)
            shade = si.is_valid() & ~last & (depth + 1 < self.max_depth)
            bsdf = si.bsdf(ray)
            # The scene's emitters: the environment and directional lights.
            ds, em_weight = scene.sample_emitter_direction(si, sampler.next_2d(), True, shade)
            bsdf_val, bsdf_pdf = bsdf.eval_pdf(ctx, si, si.to_local(ds.d), shade)
            mis = dr.select(ds.delta, 1.0, ds.pdf / dr.maximum(ds.pdf + bsdf_pdf, 1e-30))
            L[shade] += beta * mis * bsdf_val * em_weight
            # manylights' lights, every one.
            i = mi.UInt32(0)
            while shade & (i < n):
                to_light = self.gather3(self.position, i, mi.Point3f) - si.p
                dist = dr.norm(to_light)
                l = to_light / dist
                axis = self.gather3(self.axis, i, mi.Vector3f)
                c = dr.clip(dr.dot(-l, axis) * dr.gather(mi.Float, self.cone_scale, i) + dr.gather(mi.Float, self.cone_offset, i), 0.0, 1.0)
                falloff = dr.square(1.0 - dist / dr.gather(mi.Float, self.radius, i)) * c * c
                lit = (dist < dr.gather(mi.Float, self.radius, i)) & (falloff > 0.0) & (dr.dot(l, si.n) > 0.0)
                lit &= ~scene.ray_test(si.spawn_ray_to(si.p + to_light), lit)
                L[lit] += beta * bsdf.eval(ctx, si, si.to_local(l), lit) * self.gather3(self.colour, i, mi.Color3f) * falloff
                i += 1
            bs, weight = bsdf.sample(ctx, si, sampler.next_1d(), sampler.next_2d(), shade)
            beta *= weight
            prev_si = dr.detach(si, True)
            prev_pdf = bs.pdf
            prev_delta = mi.has_flag(bs.sampled_type, mi.BSDFFlags.Delta)
            # Direct light only: after a non-delta bounce the path only looks for an emitter.
            last = self.direct & ~prev_delta
            ray = si.spawn_ray(si.to_world(bs.wo))
            depth += 1
            active = shade & (bs.pdf > 0.0)
        return L, valid, []

    def aov_names(self):
        return []

    def to_string(self):
        return f"RadiusLimitedPath[{self.count} lights, direct={self.direct}]"


def unit(v):
    length = math.sqrt(sum(x * x for x in v))
    return [x / length for x in v]


def cone(light):
    """A spot's cone as manylights keeps it (LightCone): the factor before squaring is
    clamp(cos · scale + offset); a point light's is 1 everywhere."""
    if "inner_deg" not in light:
        return 0.0, 1.0
    ci, co = math.cos(math.radians(light["inner_deg"])), math.cos(math.radians(light["outer_deg"]))
    scale = 1.0 / max(ci - co, 1e-3)
    return scale, -co * scale


# ---------------------------------------------------------------- glTF's material


def charlie_d(n_dot_h, roughness):
    r = max(roughness, 0.07)
    inv = 1.0 / (r * r)
    sin2 = dr.maximum(1.0 - n_dot_h * n_dot_h, 0.0)
    return (2.0 + inv) * dr.power(sin2, 0.5 * inv) / (2.0 * math.pi)


def charlie_fit(alpha):
    """The coefficients (a, b, c, d, e) of Estevez and Kulla's fit of the Charlie sheen's Λ,
    a / (1 + b·x^c) + d·x + e, at α."""
    t = (1.0 - alpha) ** 2
    return tuple(u + (v - u) * t for u, v in [(21.5473, 25.3245), (3.82987, 3.32435), (0.19823, 0.16801), (-1.97760, -1.27393), (-4.32054, -4.85967)])


def charlie_lambda(cos_theta, alpha):
    a, b, c, d, e = charlie_fit(alpha)
    fit = lambda x: a / (1.0 + b * dr.power(x, c)) + d * x + e
    return dr.select(cos_theta < 0.5, dr.exp(fit(cos_theta)), dr.exp(2.0 * fit(0.5) - fit(1.0 - cos_theta)))


def charlie_v(n_dot_l, n_dot_v, roughness):
    alpha = max(roughness, 0.07) ** 2
    return dr.clip(1.0 / ((1.0 + charlie_lambda(n_dot_v, alpha) + charlie_lambda(n_dot_l, alpha)) * (4.0 * n_dot_v * n_dot_l)), 0.0, 1.0)


def sheen_albedo_table(roughness, size=64, steps=256):
    """E(n·v) of the Charlie sheen at `roughness`, n·v from 0 to 1 in size − 1 steps: its
    directional albedo, integrated over the hemisphere (numpy, midpoint rule)."""
    r = max(roughness, 0.07)
    inv = 1.0 / (r * r)
    a, b, c, d, e = charlie_fit(r * r)

    def lam(x):
        fit = lambda y: a / (1.0 + b * np.power(y, c)) + d * y + e
        return np.where(x < 0.5, np.exp(fit(np.minimum(x, 0.5))), np.exp(2.0 * fit(0.5) - fit(np.clip(1.0 - x, 0.0, 1.0))))

    cos_l = (np.arange(steps) + 0.5) / steps
    phi = (np.arange(2 * steps) + 0.5) / (2 * steps) * 2 * math.pi
    cl, ph = np.meshgrid(cos_l, phi, indexing="ij")
    sl = np.sqrt(1 - cl * cl)
    l = np.stack([sl * np.cos(ph), sl * np.sin(ph), cl], -1)
    table = []
    for n_dot_v in np.maximum(np.linspace(0.0, 1.0, size), 1e-4):
        v = np.array([math.sqrt(1 - n_dot_v * n_dot_v), 0.0, n_dot_v])
        h = l + v
        h /= np.linalg.norm(h, axis=-1, keepdims=True)
        dd = (2.0 + inv) * np.power(np.maximum(1 - h[..., 2] ** 2, 0), 0.5 * inv) / (2 * math.pi)
        vv = np.clip(1.0 / ((1.0 + lam(n_dot_v) + lam(cl)) * (4.0 * n_dot_v * cl)), 0, 1)
        table.append(min((dd * vv * cl).mean() * 2 * math.pi, 1.0))
    return table


def ggx_d_vis(h, n_dot_l, n_dot_v, roughness):
    """GGX's D at the half vector `h` (in the shading frame) times Smith's height-correlated
    visibility V = G / (4 n·l n·v), α = roughness² (at least 10⁻⁴). D's denominator
    (n·h)²(α² − 1) + 1 is written sin²θ + cos²θ·α² with sin²θ from h's tangent components:
    in 32-bit floats the first form is 0 at n·h = 1 for a smooth surface (D infinite)."""
    a2 = dr.square(dr.maximum(dr.square(roughness), 1e-4))
    sin2, cos2 = dr.square(h.x) + dr.square(h.y), dr.square(h.z)
    d = a2 / (math.pi * dr.square(sin2 + cos2 * a2))
    return d * 0.5 / (n_dot_l * dr.sqrt(n_dot_v * n_dot_v * (1.0 - a2) + a2) + n_dot_v * dr.sqrt(n_dot_l * n_dot_l * (1.0 - a2) + a2))


def bitmap(filename, raw):
    """A texture of Mitsuba's from an image file (raw: its values as they are, else sRGB)."""
    return mi.load_dict({"type": "bitmap", "filename": str(filename), "raw": raw})


class GltfBSDF(mi.BSDF):
    """glTF's metallic-roughness material (Lambert diffuse, GGX specular with Smith
    height-correlated visibility, Schlick's Fresnel at v·h, F₀ 0.04 for dielectrics), with
    KHR_materials_sheen (Charlie distribution and visibility over the base scaled by
    1 − max(sheen)·E) and KHR_materials_clearcoat (a GGX layer of F₀ 0.04 mixed over it by
    clearcoat × Fresnel at n·v), as the specification's appendix and the extensions write it.
    Base colour, roughness and metallic may come from textures (material["maps"]: image files,
    the colour sRGB, the others grey), each times its factor. Sampled as a mixture of
    cosine-weighted and GGX visible-normal lobes."""

    def __init__(self, props, material):
        mi.BSDF.__init__(self, props)
        self.albedo = material["albedo"]
        self.roughness = material["roughness"]
        self.metallic = material["metallic"]
        maps = material.get("maps", {})
        self.albedo_map = bitmap(maps["baseColor"], False) if "baseColor" in maps else None
        self.roughness_map = bitmap(maps["roughness"], True) if "roughness" in maps else None
        self.metallic_map = bitmap(maps["metallic"], True) if "metallic" in maps else None
        self.coat, self.coat_roughness = material.get("clearcoat", (0.0, 0.0))
        self.sheen, self.sheen_roughness = material.get("sheen", ([0.0, 0.0, 0.0], 0.0))
        self.sheen_max = max(self.sheen)
        self.sheen_table = mi.Float(sheen_albedo_table(self.sheen_roughness)) if self.sheen_max > 0 else None
        flags = mi.BSDFFlags.DiffuseReflection | mi.BSDFFlags.GlossyReflection | mi.BSDFFlags.FrontSide
        self.m_components = [flags]
        self.m_flags = flags

    def at(self, si):
        """Base colour, roughness and metallic at the surface point."""
        albedo = mi.Color3f(self.albedo)
        if self.albedo_map is not None:
            albedo *= self.albedo_map.eval(si)
        roughness, metallic = mi.Float(self.roughness), mi.Float(self.metallic)
        if self.roughness_map is not None:
            roughness *= self.roughness_map.eval_1(si)
        if self.metallic_map is not None:
            metallic *= self.metallic_map.eval_1(si)
        return albedo, roughness, metallic

    def weights(self, metallic):
        """The sampling mixture's weights: diffuse (cosine), base specular, coat (GGX)."""
        w = [dr.maximum(1.0 - metallic, 0.0) + self.sheen_max, mi.Float(1.0), mi.Float(self.coat)]
        total = w[0] + w[1] + w[2]
        return [x / total for x in w]

    def sheen_albedo(self, cos_theta):
        size = 64
        x = dr.clip(cos_theta, 0.0, 1.0) * (size - 1)
        i = mi.UInt32(dr.minimum(dr.floor(x), size - 2))
        f = x - mi.Float(i)
        return dr.lerp(dr.gather(mi.Float, self.sheen_table, i), dr.gather(mi.Float, self.sheen_table, i + 1), f)

    def ggx(self, roughness):
        return mi.MicrofacetDistribution(mi.MicrofacetType.GGX, dr.maximum(roughness * roughness, 1e-4), True)

    def value(self, si, wo, active):
        wi = si.wi
        albedo, roughness, metallic = self.at(si)
        n_dot_v, n_dot_l = mi.Frame3f.cos_theta(wi), mi.Frame3f.cos_theta(wo)
        active &= (n_dot_v > 0.0) & (n_dot_l > 0.0)
        h = dr.normalize(wi + wo)
        n_dot_h, v_dot_h = mi.Frame3f.cos_theta(h), dr.dot(wi, h)
        d_vis = ggx_d_vis(h, n_dot_l, n_dot_v, roughness)
        fc = dr.power(1.0 - dr.abs(v_dot_h), 5.0)
        f_dielectric = 0.04 + 0.96 * fc
        f_metal = albedo + (1.0 - albedo) * fc
        dielectric = (1.0 - f_dielectric) * albedo / math.pi + f_dielectric * d_vis
        base = dr.lerp(dielectric, f_metal * d_vis, metallic)
        if self.sheen_max > 0.0:
            scale = dr.minimum(1.0 - self.sheen_max * self.sheen_albedo(n_dot_v), 1.0 - self.sheen_max * self.sheen_albedo(n_dot_l))
            base = base * scale + mi.Color3f(self.sheen) * charlie_d(n_dot_h, self.sheen_roughness) * charlie_v(n_dot_l, n_dot_v, self.sheen_roughness)
        if self.coat > 0.0:
            fr = self.coat * (0.04 + 0.96 * dr.power(1.0 - n_dot_v, 5.0))
            base = base * (1.0 - fr) + fr * ggx_d_vis(h, n_dot_l, n_dot_v, mi.Float(self.coat_roughness))
        return dr.select(active, base * n_dot_l, 0.0)

    def density(self, si, wo, active):
        wi = si.wi
        _, roughness, metallic = self.at(si)
        weights = self.weights(metallic)
        active &= (mi.Frame3f.cos_theta(wi) > 0.0) & (mi.Frame3f.cos_theta(wo) > 0.0)
        h = dr.normalize(wi + wo)
        pdf = weights[0] * mi.warp.square_to_cosine_hemisphere_pdf(wo)
        pdf += weights[1] * self.ggx(roughness).pdf(wi, h) / (4.0 * dr.abs(dr.dot(wo, h)))
        if self.coat > 0.0:
            pdf += weights[2] * self.ggx(mi.Float(self.coat_roughness)).pdf(wi, h) / (4.0 * dr.abs(dr.dot(wo, h)))
        return dr.select(active, pdf, 0.0)

    def sample(self, ctx, si, sample1, sample2, active):
        bs = dr.zeros(mi.BSDFSample3f)
        _, roughness, metallic = self.at(si)
        weights = self.weights(metallic)
        diffuse = sample1 < weights[0]
        coat = sample1 >= weights[0] + weights[1]
        m_base, _ = self.ggx(roughness).sample(si.wi, sample2)
        m_coat, _ = self.ggx(mi.Float(self.coat_roughness)).sample(si.wi, sample2)
        m = dr.select(coat, m_coat, m_base)
        wo = dr.select(diffuse, mi.warp.square_to_cosine_hemisphere(sample2), mi.reflect(si.wi, m))
        bs.wo = wo
        bs.pdf = self.density(si, wo, active)
        bs.eta = 1.0
        bs.sampled_type = mi.UInt32(+mi.BSDFFlags.GlossyReflection)
        bs.sampled_component = mi.UInt32(0)
        active &= bs.pdf > 0.0
        return bs, dr.select(active, self.value(si, wo, active) / dr.maximum(bs.pdf, 1e-30), 0.0)

    def eval(self, ctx, si, wo, active=True):
        return self.value(si, wo, active)

    def pdf(self, ctx, si, wo, active=True):
        return self.density(si, wo, active)

    def eval_pdf(self, ctx, si, wo, active=True):
        return self.value(si, wo, active), self.density(si, wo, active)

    def traverse(self, callback):
        pass

    def to_string(self):
        return "GltfBSDF"
