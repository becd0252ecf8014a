//! CPU reference of the shading models, formula for formula the same as the GLSL
//! (`shaders/common/seed_brdf.glsl`; keep in sync). Image tests shade analytically known
//! surface points with these and compare the GPU's pixels.

use crate::gpu_types::PointLight;
use crate::material::Material;
use glam::Vec3;
use std::f32::consts::PI;

pub(crate) fn d_ggx(n_dot_h: f32, roughness: f32) -> f32 {
    let alpha = roughness * roughness;
    let alpha2 = alpha * alpha;
    let denom = n_dot_h * n_dot_h * (alpha2 - 1.0) + 1.0;
    alpha2 / (PI * denom * denom)
}

/// Schlick–Smith G / (4 NdotL NdotV), written so grazing views give no 0/0 (see the GLSL).
pub(crate) fn g_schlick_smith_over_4nlnv(n_dot_l: f32, n_dot_v: f32, roughness: f32) -> f32 {
    let r = roughness + 1.0;
    let k = r * r / 8.0;
    0.25 / ((n_dot_l * (1.0 - k) + k) * (n_dot_v * (1.0 - k) + k))
}

fn f_schlick(cos_theta: f32, albedo: Vec3, metallic: f32) -> Vec3 {
    let f0 = Vec3::splat(0.04).lerp(albedo, metallic);
    f0 + (Vec3::ONE - f0) * (1.0 - cos_theta).powf(5.0)
}

/// Where one point light meets a surface point: the cosines and the radiance it brings,
/// falloff (1 − d/r)² · N·L.
pub(crate) struct LightAt {
    pub n_dot_v: f32,
    pub n_dot_l: f32,
    pub n_dot_h: f32,
    pub radiance: f32,
    /// Towards the light, the half vector, and the falloff (1 − d/r)² alone.
    pub l: Vec3,
    pub h: Vec3,
    pub falloff: f32,
}

/// Light `light` at point `p` (unit normal `n`, towards the eye `v`); None beyond its radius or
/// behind the surface, where every model's light is exactly zero.
pub(crate) fn light_at(light: &PointLight, p: Vec3, n: Vec3, v: Vec3) -> Option<LightAt> {
    let to_light = Vec3::from_slice(&light.position_radius[..3]) - p;
    let dist = to_light.length();
    let radius = light.position_radius[3];
    if dist > radius {
        return None;
    }
    let l = to_light / dist;
    let h = (v + l).normalize();
    let n_dot_l = n.dot(l).clamp(0.0, 1.0);
    if n_dot_l <= 0.0 {
        return None;
    }
    let atten = (1.0 - dist / radius).clamp(0.0, 1.0);
    let falloff = atten * atten;
    Some(LightAt {
        n_dot_v: n.dot(v).clamp(0.0, 1.0),
        n_dot_l,
        n_dot_h: n.dot(h).clamp(0.0, 1.0),
        radiance: falloff * n_dot_l,
        l,
        h,
        falloff,
    })
}

/// One light's contribution under the seed's Cook–Torrance terms (exactly zero beyond its
/// radius): the `seed` model (specular only, N·L twice) or, with `pbr`, the `pbr` model
/// (Lambert diffuse weighted by (1 − F)(1 − metallic), N·L once) — cook_torrance_point_light.
fn cook_torrance_point_light(light: &PointLight, p: Vec3, n: Vec3, v: Vec3, m: &Material, pbr: bool) -> Vec3 {
    let Some(LightAt { n_dot_v, n_dot_l, n_dot_h, radiance, .. }) = light_at(light, p, n, v) else { return Vec3::ZERO };
    let f = f_schlick(n_dot_v, m.albedo, m.metallic);
    let spec = d_ggx(n_dot_h, m.roughness) * f * g_schlick_smith_over_4nlnv(n_dot_l, n_dot_v, m.roughness.max(0.05));
    let color = Vec3::from_slice(&light.color[..3]);
    if pbr {
        let diffuse = (Vec3::ONE - f) * (1.0 - m.metallic) * m.albedo / PI;
        return (diffuse + spec) * color * radiance;
    }
    spec * n_dot_l * color * radiance
}

/// One light's contribution in the `seed` model; exactly zero beyond its radius.
pub fn seed_point_light(light: &PointLight, p: Vec3, n: Vec3, v: Vec3, m: &Material) -> Vec3 {
    cook_torrance_point_light(light, p, n, v, m, false)
}

/// One light's contribution in the `pbr` model; exactly zero beyond its radius.
pub fn pbr_point_light(light: &PointLight, p: Vec3, n: Vec3, v: Vec3, m: &Material) -> Vec3 {
    cook_torrance_point_light(light, p, n, v, m, true)
}

/// Linear colour of surface point `p` with unit normal `n` seen from `eye` (`seed` model).
pub fn shade_seed(p: Vec3, n: Vec3, eye: Vec3, m: &Material, lights: &[PointLight], ambient: f32) -> Vec3 {
    let v = (eye - p).normalize();
    let lo: Vec3 = lights.iter().map(|l| seed_point_light(l, p, n, v, m)).sum();
    m.albedo * ambient + lo
}

/// The pbr model's tone map before its gamma (ACES, Narkowicz 2015's fit; shading_model.glsl).
pub fn aces_tone_map(x: Vec3) -> Vec3 {
    (x * (2.51 * x + 0.03) / (x * (2.43 * x + 0.59) + 0.14)).clamp(Vec3::ZERO, Vec3::ONE)
}

/// The seed's output encoding: gamma 1/2.2, then 8-bit UNORM (round to nearest, clamped).
pub fn encode_gamma_unorm8(c: Vec3) -> [u8; 3] {
    c.to_array().map(|x| (x.max(0.0).powf(1.0 / 2.2).min(1.0) * 255.0).round() as u8)
}

#[cfg(test)]
mod tests {
    use super::*;

    fn gold() -> Material {
        Material::named("gold").unwrap()
    }

    fn light(at: Vec3, radius: f32) -> PointLight {
        PointLight { position_radius: [at.x, at.y, at.z, radius], color: [1.0, 1.0, 1.0, 0.0] }
    }

    #[test]
    fn nothing_beyond_the_radius_and_continuous_to_zero_at_it() {
        let (p, n, v) = (Vec3::ZERO, Vec3::Y, Vec3::Y);
        assert_eq!(seed_point_light(&light(Vec3::new(0.0, 2.0, 0.0), 1.99), p, n, v, &gold()), Vec3::ZERO);
        let just_inside = seed_point_light(&light(Vec3::new(0.0, 2.0, 0.0), 2.00001), p, n, v, &gold());
        assert!(just_inside.max_element() < 1e-6 && just_inside.max_element() >= 0.0);
    }

    #[test]
    fn mirror_direction_matches_the_formula_by_hand() {
        // Light and eye straight above: N·L = N·V = N·H = 1, so D = 1/(π α²), F = F0 = albedo,
        // G/(4 NL NV) = 1/4, radiance = (1 − d/r)².
        let m = Material { albedo: Vec3::new(0.5, 0.25, 1.0), roughness: 0.5, metallic: 1.0 };
        let c = seed_point_light(&light(Vec3::new(0.0, 1.0, 0.0), 4.0), Vec3::ZERO, Vec3::Y, Vec3::Y, &m);
        let alpha = 0.25f32;
        let expected = m.albedo * (1.0 / (PI * alpha * alpha)) * 0.25 * 0.75f32.powi(2);
        assert!((c - expected).abs().max_element() < 1e-5, "{c} vs {expected}");
    }

    #[test]
    fn grazing_view_is_finite() {
        let c = seed_point_light(&light(Vec3::new(0.0, 1.0, 0.0), 4.0), Vec3::ZERO, Vec3::Y, Vec3::X, &gold());
        assert!(c.is_finite());
    }

    #[test]
    fn gamma_encoding_rounds_and_clamps() {
        assert_eq!(encode_gamma_unorm8(Vec3::new(0.0, 1.0, 4.0)), [0, 255, 255]);
        assert_eq!(encode_gamma_unorm8(Vec3::splat(0.5))[0], (0.5f32.powf(1.0 / 2.2) * 255.0).round() as u8);
    }
}
