//! What glTF's PBR extensions add to a metallic-roughness material, and the pbr model's light
//! with them: a dielectric's reflectance from its index of refraction
//! (KHR_materials_ior) scaled and tinted (KHR_materials_specular), a clear coat over the base
//! (KHR_materials_clearcoat), cloth-like sheen (KHR_materials_sheen, the Charlie distribution of
//! Estevez and Kulla 2017)), unlit surfaces (KHR_materials_unlit), and light let through
//! (KHR_materials_transmission, thin-walled, tinted by KHR_materials_volume's attenuation over
//! its thickness: `lobed_transmittance`; the transparent layers blend what lies behind
//! through it, straight on, without refraction). Formula for formula the CPU reference of
//! shaders/common/material_lobes.glsl (keep in sync; tests compare them).
//!
//! With every extension at its default the lobed light is the pbr model's (same formulas
//! rearranged), so a file that names an extension without changing anything renders as one
//! that does not: the GPU compiles the lobes only for scenes that use them.

use crate::gpu_types::PointLight;
use crate::material::Material;
use crate::shading::{d_ggx, g_schlick_smith_over_4nlnv, light_at, LightAt};
use glam::Vec3;
use std::f32::consts::PI;

/// A material's parts beyond metallic-roughness (glTF's defaults: none).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct MaterialLobes {
    /// Index of refraction: a dielectric reflects ((ior − 1)/(ior + 1))² at normal incidence.
    pub ior: f32,
    /// Scales a dielectric's specular reflection (and what it takes from the diffuse).
    pub specular: f32,
    /// Tints a dielectric's reflectance at normal incidence (may exceed 1; the product is
    /// clamped to 1).
    pub specular_color: Vec3,
    /// The clear coat's strength (0: none) and roughness.
    pub clearcoat: f32,
    pub clearcoat_roughness: f32,
    /// The sheen's colour (black: none) and roughness.
    pub sheen_color: Vec3,
    pub sheen_roughness: f32,
    /// Shown as its base colour, no light computed.
    pub unlit: bool,
    /// How much of the light a dielectric does not reflect passes through it (tinted by its
    /// base colour) instead of being scattered diffusely: 0 none, 1 all.
    pub transmission: f32,
    /// The volume's colour after `attenuation_distance` inside it (Beer's law); with
    /// `thickness`, in world units, what the light passing through keeps.
    pub attenuation_color: Vec3,
    pub attenuation_distance: f32,
    pub thickness: f32,
    /// Scales the clear coat's normal map's tangent-space x and y.
    pub clearcoat_normal_scale: f32,
}

/// What an object's extension textures (`ObjectTextures`) give at a point, each multiplying
/// its factor (1: no texture).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct LobeTexels {
    pub clearcoat: f32,
    pub clearcoat_roughness: f32,
    pub sheen_color: Vec3,
    pub sheen_roughness: f32,
    pub specular: f32,
    pub specular_color: Vec3,
    pub transmission: f32,
    pub thickness: f32,
}

impl Default for LobeTexels {
    fn default() -> LobeTexels {
        LobeTexels {
            clearcoat: 1.0,
            clearcoat_roughness: 1.0,
            sheen_color: Vec3::ONE,
            sheen_roughness: 1.0,
            specular: 1.0,
            specular_color: Vec3::ONE,
            transmission: 1.0,
            thickness: 1.0,
        }
    }
}

impl Default for MaterialLobes {
    fn default() -> MaterialLobes {
        MaterialLobes {
            ior: 1.5,
            specular: 1.0,
            specular_color: Vec3::ONE,
            clearcoat: 0.0,
            clearcoat_roughness: 0.0,
            sheen_color: Vec3::ZERO,
            sheen_roughness: 0.0,
            unlit: false,
            transmission: 0.0,
            attenuation_color: Vec3::ONE,
            attenuation_distance: f32::INFINITY,
            thickness: 0.0,
            clearcoat_normal_scale: 1.0,
        }
    }
}

impl MaterialLobes {
    /// Whether shading with these lobes differs from shading without (the scene's pipelines
    /// compile the lobes only where some object's do).
    pub fn any(&self) -> bool {
        *self != MaterialLobes::default()
    }

    /// A dielectric's reflectance at normal incidence: F₀ of the index of refraction times the
    /// specular colour, at most 1.
    pub fn dielectric_f0(&self) -> Vec3 {
        self.dielectric_f0_unclamped().min(Vec3::ONE)
    }

    /// F₀ of the index of refraction times the specular colour, as the object buffer keeps it
    /// (the shaders clamp it after the specular colour texture's texel multiplies it).
    fn dielectric_f0_unclamped(&self) -> Vec3 {
        let r = (self.ior - 1.0) / (self.ior + 1.0);
        r * r * self.specular_color
    }

    /// These lobes at a point where the extension textures give `t`: each factor times its
    /// texel (the shaders' point_material does the same).
    pub fn textured(&self, t: &LobeTexels) -> MaterialLobes {
        MaterialLobes {
            clearcoat: self.clearcoat * t.clearcoat,
            clearcoat_roughness: self.clearcoat_roughness * t.clearcoat_roughness,
            sheen_color: self.sheen_color * t.sheen_color,
            sheen_roughness: self.sheen_roughness * t.sheen_roughness,
            specular: self.specular * t.specular,
            specular_color: self.specular_color * t.specular_color,
            transmission: self.transmission * t.transmission,
            thickness: self.thickness * t.thickness,
            ..*self
        }
    }

    /// A dielectric's Fresnel reflectance at Schlick's weight `fc` = (1 − n·v)⁵, scaled by the
    /// specular factor.
    pub fn dielectric_fresnel(&self, fc: f32) -> Vec3 {
        let f0 = self.dielectric_f0();
        self.specular * (f0 + (Vec3::ONE - f0) * fc)
    }

    /// What light passing through keeps of each channel after crossing the volume's
    /// thickness: attenuation colour ^ (thickness / attenuation distance); all of it for a
    /// thin wall (thickness 0) or a clear volume.
    pub fn volume_transmittance(&self) -> Vec3 {
        if self.thickness <= 0.0 || !self.attenuation_distance.is_finite() {
            return Vec3::ONE;
        }
        self.attenuation_color.powf(self.thickness / self.attenuation_distance)
    }

    /// ObjectData::lobes: (dielectric F₀ before its clamp to 1, specular factor), (clear coat,
    /// its roughness, unlit, transmission), (sheen colour, sheen roughness), (volume
    /// transmittance over the whole thickness factor, clear coat normal scale).
    pub fn vectors(&self) -> [[f32; 4]; 4] {
        [
            self.dielectric_f0_unclamped().extend(self.specular).to_array(),
            [self.clearcoat, self.clearcoat_roughness, f32::from(u8::from(self.unlit)), self.transmission],
            self.sheen_color.extend(self.sheen_roughness).to_array(),
            self.volume_transmittance().extend(self.clearcoat_normal_scale).to_array(),
        ]
    }
}

/// Side of the sheen's directional-albedo table: n·v along one axis, roughness along the other,
/// each from 0 to 1 in SHEEN_TABLE_SIZE − 1 steps.
pub const SHEEN_TABLE_SIZE: usize = 16;

/// The smallest sheen roughness the Charlie distribution is evaluated at (its exponent 1/α²
/// grows without bound towards 0).
pub const SHEEN_MIN_ROUGHNESS: f32 = 0.07;

/// The Charlie sheen distribution (Estevez and Kulla 2017) at n·h.
pub fn d_charlie(n_dot_h: f32, roughness: f32) -> f32 {
    let r = roughness.max(SHEEN_MIN_ROUGHNESS);
    let inv_alpha = 1.0 / (r * r);
    let sin2 = (1.0 - n_dot_h * n_dot_h).max(0.0);
    (2.0 + inv_alpha) * sin2.powf(0.5 * inv_alpha) / (2.0 * PI)
}

/// The Charlie sheen's Λ (Estevez and Kulla 2017's fit, as glTF's sample viewer writes it).
fn lambda_sheen(cos_theta: f32, alpha: f32) -> f32 {
    let t = (1.0 - alpha) * (1.0 - alpha);
    let mix = |a: f32, b: f32| a + (b - a) * t;
    let fit = |x: f32| {
        mix(21.5473, 25.3245) / (1.0 + mix(3.82987, 3.32435) * x.powf(mix(0.19823, 0.16801)))
            + mix(-1.97760, -1.27393) * x
            + mix(-4.32054, -4.85967)
    };
    if cos_theta < 0.5 {
        fit(cos_theta).exp()
    } else {
        (2.0 * fit(0.5) - fit(1.0 - cos_theta)).exp()
    }
}

/// The Charlie sheen's visibility, G / (4 n·l n·v), at most 1.
pub fn v_charlie(n_dot_l: f32, n_dot_v: f32, roughness: f32) -> f32 {
    let r = roughness.max(SHEEN_MIN_ROUGHNESS);
    let alpha = r * r;
    (1.0 / ((1.0 + lambda_sheen(n_dot_v, alpha) + lambda_sheen(n_dot_l, alpha)) * (4.0 * n_dot_v * n_dot_l))).clamp(0.0, 1.0)
}

/// The sheen lobe's directional albedo E(n·v, roughness): how much of the light it reflects,
/// integrated over the hemisphere (`cos_steps` × `phi_steps` directions), at most 1 (towards a
/// grazing view the fit's visibility lets it pass 1). The table below holds it at the grid
/// points; a test checks them.
pub fn sheen_albedo_integral(n_dot_v: f32, roughness: f32, cos_steps: u32, phi_steps: u32) -> f32 {
    let n_dot_v = n_dot_v.max(1e-4);
    let v = Vec3::new((1.0 - n_dot_v * n_dot_v).sqrt(), 0.0, n_dot_v);
    let mut sum = 0f64;
    for i in 0..cos_steps {
        // Uniform in cos θ: dω = d(cos θ) dφ.
        let cos_l = (i as f32 + 0.5) / cos_steps as f32;
        let sin_l = (1.0 - cos_l * cos_l).sqrt();
        for j in 0..phi_steps {
            let phi = (j as f32 + 0.5) / phi_steps as f32 * 2.0 * PI;
            let l = Vec3::new(sin_l * phi.cos(), sin_l * phi.sin(), cos_l);
            let h = (v + l).normalize();
            sum += f64::from(d_charlie(h.z, roughness) * v_charlie(cos_l, n_dot_v, roughness) * cos_l);
        }
    }
    ((sum * f64::from(2.0 * PI) / f64::from(cos_steps * phi_steps)) as f32).min(1.0)
}

/// E(n·v, roughness) at the grid points: row r (roughness r/15), column c (n·v c/15); made by
/// integrating as `sheen_albedo_integral(_, _, 1024, 512)` does. The shaders read it from
/// EnvironmentData.
#[rustfmt::skip]
pub const SHEEN_ALBEDO: [f32; SHEEN_TABLE_SIZE * SHEEN_TABLE_SIZE] = include!("material_lobes/sheen_albedo.in");

/// E at (n·v, roughness), bilinear between the table's grid points (as the shader reads it).
pub fn sheen_albedo(n_dot_v: f32, roughness: f32) -> f32 {
    let top = (SHEEN_TABLE_SIZE - 1) as f32;
    let (x, y) = (n_dot_v.clamp(0.0, 1.0) * top, roughness.clamp(0.0, 1.0) * top);
    let (x0, y0) = (x.floor().min(top - 1.0), y.floor().min(top - 1.0));
    let (fx, fy) = (x - x0, y - y0);
    let at = |c: f32, r: f32| SHEEN_ALBEDO[r as usize * SHEEN_TABLE_SIZE + c as usize];
    let low = at(x0, y0) + (at(x0 + 1.0, y0) - at(x0, y0)) * fx;
    let high = at(x0, y0 + 1.0) + (at(x0 + 1.0, y0 + 1.0) - at(x0, y0 + 1.0)) * fx;
    low + (high - low) * fy
}

/// One point light's contribution in the pbr model with `lobes` (zero beyond its radius and
/// behind the surface): F = mix(specular·Schlick(dielectric F₀), Schlick(albedo), metallic),
/// Lambert diffuse weighted by (1 − F)(1 − metallic)(1 − transmission) plus GGX specular; the
/// sheen's lobe with the base scaled by 1 − max(sheen)·E at the view and the light; the clear
/// coat's GGX lobe (F₀ 0.04) over the base scaled by 1 − coat·F_coat, the coat's cosines (and
/// its Fresnel term) taken about its own normal `coat_n`.
pub fn lobed_point_light(light: &PointLight, p: Vec3, (n, coat_n): (Vec3, Vec3), v: Vec3, m: &Material, lobes: &MaterialLobes) -> Vec3 {
    let Some(LightAt { n_dot_v, n_dot_l, n_dot_h, radiance, l, h, falloff }) = light_at(light, p, n, v) else { return Vec3::ZERO };
    let fc = (1.0 - n_dot_v).powf(5.0);
    let f_dielectric = lobes.dielectric_fresnel(fc);
    let f_metal = m.albedo + (Vec3::ONE - m.albedo) * fc;
    let f = f_dielectric.lerp(f_metal, m.metallic);
    let g = g_schlick_smith_over_4nlnv(n_dot_l, n_dot_v, m.roughness.max(0.05));
    let diffuse = (Vec3::ONE - f) * (1.0 - m.metallic) * (1.0 - lobes.transmission) * m.albedo / PI;
    let mut base = diffuse + d_ggx(n_dot_h, m.roughness) * f * g;
    let sheen_max = lobes.sheen_color.max_element();
    if sheen_max > 0.0 {
        let r = lobes.sheen_roughness;
        base *= (1.0 - sheen_max * sheen_albedo(n_dot_v, r)).min(1.0 - sheen_max * sheen_albedo(n_dot_l, r));
        base += lobes.sheen_color * d_charlie(n_dot_h, r) * v_charlie(n_dot_l, n_dot_v, r);
    }
    let color = Vec3::from_slice(&light.color[..3]);
    if lobes.clearcoat <= 0.0 {
        return base * color * radiance;
    }
    let r = lobes.clearcoat_roughness;
    let (coat_v, coat_l, coat_h) = (coat_n.dot(v).clamp(0.0, 1.0), coat_n.dot(l).clamp(0.0, 1.0), coat_n.dot(h).clamp(0.0, 1.0));
    let f_coat = coat_fresnel(coat_v, lobes.clearcoat);
    let coat = if coat_l > 0.0 { f_coat * d_ggx(coat_h, r) * g_schlick_smith_over_4nlnv(coat_l, coat_v, r.max(0.05)) } else { 0.0 };
    (base * (1.0 - f_coat) * radiance + Vec3::splat(coat * falloff * coat_l)) * color
}

/// The clear coat's Fresnel reflectance at n·v (F₀ 0.04), times its strength.
fn coat_fresnel(n_dot_v: f32, clearcoat: f32) -> f32 {
    clearcoat * (0.04 + 0.96 * (1.0 - n_dot_v).powf(5.0))
}

/// What the clear coat lets through of what lies under it: 1 − coat·F_coat at the view.
pub fn coat_transmittance(n_dot_v: f32, clearcoat: f32) -> f32 {
    1.0 - coat_fresnel(n_dot_v.clamp(0.0, 1.0), clearcoat)
}

/// What a surface with `lobes` lets through of the light behind it, seen at `n_dot_v` (and
/// `coat_n_dot_v` about the coat's normal): transmission × (1 − metallic) × base colour ×
/// (1 − F) of the dielectric's Fresnel term, × 1 − coat·F_coat, × the volume's transmittance
/// — the share its light scatters diffusely without transmission (zero for none).
pub fn lobed_transmittance((n_dot_v, coat_n_dot_v): (f32, f32), m: &Material, lobes: &MaterialLobes) -> Vec3 {
    if lobes.transmission <= 0.0 {
        return Vec3::ZERO;
    }
    let n_dot_v = n_dot_v.clamp(0.0, 1.0);
    let f_dielectric = lobes.dielectric_fresnel((1.0 - n_dot_v).powf(5.0));
    let through = lobes.transmission * (1.0 - m.metallic) * coat_transmittance(coat_n_dot_v, lobes.clearcoat);
    (Vec3::ONE - f_dielectric) * m.albedo * lobes.volume_transmittance() * through
}

/// Linear colour of surface point `p` with unit normal `n` seen from `eye` in the pbr model
/// with `lobes` and a constant ambient light (no environment): every light, the ambient term
/// and the light it gives off (`emission`), the last two under the clear coat; an unlit
/// surface's albedo.
pub fn shade_lobed(
    p: Vec3,
    (n, coat_n): (Vec3, Vec3),
    eye: Vec3,
    (m, lobes): (&Material, &MaterialLobes),
    lights: &[PointLight],
    ambient: f32,
    emission: Vec3,
) -> Vec3 {
    if lobes.unlit {
        return m.albedo;
    }
    let v = (eye - p).normalize();
    let lo: Vec3 = lights.iter().map(|l| lobed_point_light(l, p, (n, coat_n), v, m, lobes)).sum();
    let under_coat = coat_transmittance(coat_n.dot(v), lobes.clearcoat);
    m.albedo * ambient * (1.0 - lobes.transmission) * under_coat + lo + emission * under_coat
}

#[cfg(test)]
mod tests {
    use super::*;

    fn light_above() -> PointLight {
        PointLight { position_radius: [0.3, 1.0, 0.2, 6.0], color: [2.0, 1.5, 1.0, 0.0] }
    }

    #[test]
    fn default_lobes_light_as_the_pbr_model() {
        let v = Vec3::new(-0.4, 0.8, 0.3).normalize();
        for (metallic, roughness) in [(0.0, 0.3), (1.0, 0.6), (0.4, 0.9)] {
            let m = Material { albedo: Vec3::new(0.8, 0.5, 0.2), roughness, metallic };
            let plain = crate::shading::pbr_point_light(&light_above(), Vec3::ZERO, Vec3::Y, v, &m);
            let lobed = lobed_point_light(&light_above(), Vec3::ZERO, (Vec3::Y, Vec3::Y), v, &m, &MaterialLobes::default());
            assert!((plain - lobed).abs().max_element() < 1e-5 * plain.max_element().max(1.0), "{plain} vs {lobed}");
        }
        assert!(!MaterialLobes::default().any());
        assert!(MaterialLobes::default().dielectric_f0().abs_diff_eq(Vec3::splat(0.04), 1e-7));
    }

    #[test]
    fn each_lobe_changes_the_light() {
        let m = Material { albedo: Vec3::new(0.8, 0.5, 0.2), roughness: 0.7, metallic: 0.0 };
        let v = Vec3::new(-0.7, 0.3, 0.1).normalize();
        let plain = lobed_point_light(&light_above(), Vec3::ZERO, (Vec3::Y, Vec3::Y), v, &m, &MaterialLobes::default());
        for lobes in [
            MaterialLobes { ior: 1.0, ..Default::default() },
            MaterialLobes { specular: 0.2, specular_color: Vec3::new(2.0, 0.5, 0.5), ..Default::default() },
            MaterialLobes { clearcoat: 1.0, clearcoat_roughness: 0.1, ..Default::default() },
            MaterialLobes { sheen_color: Vec3::new(0.9, 0.2, 0.6), sheen_roughness: 0.5, ..Default::default() },
        ] {
            let lit = lobed_point_light(&light_above(), Vec3::ZERO, (Vec3::Y, Vec3::Y), v, &m, &lobes);
            assert!((lit - plain).abs().max_element() > 1e-3, "{lobes:?}: {lit} vs {plain}");
        }
    }

    #[test]
    fn transmission_takes_the_diffuse_light_and_lets_the_base_colour_through() {
        let m = Material { albedo: Vec3::new(0.8, 0.5, 0.2), roughness: 0.4, metallic: 0.0 };
        let v = Vec3::new(-0.4, 0.8, 0.3).normalize();
        let glass = MaterialLobes { transmission: 1.0, ..Default::default() };
        // All of the diffuse light goes: what is left is the specular light, as of a black base.
        let lit = lobed_point_light(&light_above(), Vec3::ZERO, (Vec3::Y, Vec3::Y), v, &m, &glass);
        let black = Material { albedo: Vec3::ZERO, ..m };
        let specular = lobed_point_light(&light_above(), Vec3::ZERO, (Vec3::Y, Vec3::Y), v, &black, &MaterialLobes::default());
        assert!((lit - specular).abs().max_element() < 1e-6, "{lit} vs {specular}");
        assert_eq!(shade_lobed(Vec3::ZERO, (Vec3::Y, Vec3::Y), Vec3::new(0.0, 3.0, 0.0), (&m, &glass), &[], 0.5, Vec3::ZERO), Vec3::ZERO);
        // Head on, a dielectric of F₀ 0.04 lets 96 % of the base colour through; a volume of
        // one attenuation distance tints it once more; a metal or none lets nothing through.
        assert!(lobed_transmittance((1.0, 1.0), &m, &glass).abs_diff_eq(0.96 * m.albedo, 1e-6));
        let tinted = MaterialLobes { attenuation_color: Vec3::new(1.0, 0.5, 0.5), attenuation_distance: 2.0, thickness: 2.0, ..glass };
        assert!(lobed_transmittance((1.0, 1.0), &m, &tinted).abs_diff_eq(0.96 * m.albedo * Vec3::new(1.0, 0.5, 0.5), 1e-6));
        assert!(tinted.any() && glass.vectors()[1][3] == 1.0 && tinted.vectors()[3][1] == 0.5);
        assert_eq!(lobed_transmittance((1.0, 1.0), &Material { metallic: 1.0, ..m }, &glass), Vec3::ZERO);
        assert_eq!(lobed_transmittance((1.0, 1.0), &m, &MaterialLobes::default()), Vec3::ZERO);
        // Grazing, Fresnel reflects everything: nothing passes.
        assert!(lobed_transmittance((0.0, 0.0), &m, &glass).max_element() < 1e-6);
    }

    #[test]
    fn the_sheen_table_holds_the_integral() {
        // A few grid points against the integral at the table's own resolution; every entry in [0, 1].
        for (r, c) in [(0, 0), (3, 4), (8, 8), (15, 0), (15, 15), (10, 1)] {
            let e = sheen_albedo_integral(c as f32 / 15.0, r as f32 / 15.0, 1024, 512);
            let t = SHEEN_ALBEDO[r * SHEEN_TABLE_SIZE + c];
            assert!((e - t).abs() < 1e-4, "row {r} column {c}: table {t}, integral {e}");
        }
        assert!(SHEEN_ALBEDO.iter().all(|e| (0.0..=1.0).contains(e)));
    }

    #[test]
    fn sheen_albedo_interpolates_between_grid_points() {
        assert_eq!(sheen_albedo(1.0, 1.0), SHEEN_ALBEDO[SHEEN_TABLE_SIZE * SHEEN_TABLE_SIZE - 1]);
        assert_eq!(sheen_albedo(0.0, 0.0), SHEEN_ALBEDO[0]);
        let mid = sheen_albedo(0.5 / 15.0, 0.0);
        assert!((mid - (SHEEN_ALBEDO[0] + SHEEN_ALBEDO[1]) / 2.0).abs() < 1e-6);
    }
}
