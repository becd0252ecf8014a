//! The lights of the blinn-phong model (`--shading blinn-phong`) besides the point lights: one
//! directional light with a shadow map, one spot light, an ambient colour, and the transform
//! of the texture coordinates (the seed's `matTransform`).

use glam::{Mat2, Mat4, Vec3};

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct SpotLight {
    pub position: Vec3,
    /// Unit direction the light shines along.
    pub direction: Vec3,
    pub strength: Vec3,
    /// No light beyond this distance (the seed's fallOffEnd); linear falloff from 0.
    pub range: f32,
    /// Cone: strength × max(cos angle, 0)^power.
    pub power: f32,
}

#[derive(Clone, Copy, Debug, PartialEq)]
pub struct BlinnPhongLights {
    /// Unit direction the sunlight travels (towards the ground).
    pub sun_direction: Vec3,
    pub sun_strength: Vec3,
    pub spot: SpotLight,
    pub ambient: Vec3,
    pub texture_transform: Mat2,
}

impl Default for BlinnPhongLights {
    /// The built-in scene's: a sun from the upper left, a warm spot straight down on the
    /// middle of the grid, textures repeated twice per unit of u and v.
    fn default() -> BlinnPhongLights {
        BlinnPhongLights {
            sun_direction: Vec3::new(-0.35, -1.0, -0.25).normalize(),
            sun_strength: Vec3::splat(0.8),
            spot: SpotLight {
                position: Vec3::new(0.0, 9.0, 0.0),
                direction: -Vec3::Y,
                strength: Vec3::new(1.0, 0.85, 0.6) * 2.0,
                range: 20.0,
                power: 24.0,
            },
            ambient: Vec3::splat(0.08),
            texture_transform: Mat2::from_diagonal(glam::Vec2::splat(2.0)),
        }
    }
}

/// The directional light's view-projection for its shadow map: orthographic along
/// `direction`, fitted around the box [lo, hi] (every object), Vulkan depth 0..1 (0 nearest
/// the light). Texture coordinates of a world point are then ndc.xy · 0.5 + 0.5.
pub fn shadow_view_proj(lo: Vec3, hi: Vec3, direction: Vec3) -> Mat4 {
    let centre = (lo + hi) * 0.5;
    let radius = ((hi - lo) * 0.5).length().max(1e-3);
    let up = if direction.y.abs() > 0.99 { Vec3::Z } else { Vec3::Y };
    let view = Mat4::look_at_rh(centre - direction * (radius * 2.0), centre, up);
    let projection = Mat4::orthographic_rh(-radius, radius, -radius, radius, radius, radius * 3.0);
    projection * view
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn shadow_projection_holds_the_box_and_orders_depth_along_the_light() {
        let (lo, hi) = (Vec3::new(-10.0, -1.0, -10.0), Vec3::new(10.0, 1.0, 10.0));
        let dir = BlinnPhongLights::default().sun_direction;
        let m = shadow_view_proj(lo, hi, dir);
        for i in 0..8 {
            let corner = Vec3::new([lo.x, hi.x][i & 1], [lo.y, hi.y][(i >> 1) & 1], [lo.z, hi.z][i >> 2]);
            let c = m.project_point3(corner);
            assert!(c.x.abs() <= 1.0 && c.y.abs() <= 1.0 && (0.0..=1.0).contains(&c.z), "{corner} → {c}");
        }
        // A point further along the light's direction is deeper.
        let a = m.project_point3(Vec3::ZERO);
        let b = m.project_point3(dir);
        assert!(b.z > a.z && (b.x - a.x).abs() < 1e-5 && (b.y - a.y).abs() < 1e-5);
    }
}
