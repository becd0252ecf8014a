//! Transparency's per-pixel rule (glTF `alphaMode: BLEND`), the reference every transparent
//! path is held to: the transparent layers in front of a pixel's opaque surface are blended
//! over it back to front in linear light, each `colour · α + under · (1 − α + α · t)`, where
//! `t` is what a transmitting surface (KHR_materials_transmission) lets through of the light
//! behind it, per channel (zero for a plain BLEND surface).
//!
//! The order is the layers' depth, ties broken by their ids (the object), then by the layers
//! themselves (colour, coverage, what they let through), so the result does not depend on the
//! order in which the surfaces were listed or drawn: layers equal in all of that blend the same
//! either way. A pixel keeps at most `keep` layers exactly, the nearest; the farther ones are
//! merged into one layer behind those, which lets `Π(1 − αᵢ + αᵢ·tᵢ)` of what lies behind
//! through and whose colour is their weighted mean (weights αᵢ·(1 − the least channel of tᵢ): a
//! layer's share that does not let light through). The merge is order-independent too, exact
//! where it holds one layer and an approximation beyond, so a renderer counts the pixels it
//! merged.

use crate::material::Material;
use crate::mesh::MeshKind;
use crate::scene::{AlphaMode, Object, Scene};
use glam::{Mat4, Quat, Vec3};

/// One transparent surface in front of a pixel: its depth (nearer is smaller), an id that
/// orders surfaces at the same depth, its lit colour (linear), its coverage, and what its
/// covered share lets through of the light behind (zero: nothing, as BLEND).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layer {
    pub depth: f32,
    pub id: u32,
    pub color: Vec3,
    pub alpha: f32,
    pub transmitted: Vec3,
}

impl Layer {
    /// A BLEND surface: `color` covering `alpha` of the pixel, letting nothing through.
    pub fn blended(depth: f32, id: u32, color: Vec3, alpha: f32) -> Layer {
        Layer { depth, id, color, alpha, transmitted: Vec3::ZERO }
    }

    /// Its colour, coverage and what it lets through, as bits: what orders layers as deep and
    /// of the same id.
    fn bits(&self) -> [u32; 7] {
        let (c, t) = (self.color, self.transmitted);
        [c.x, c.y, c.z, self.alpha, t.x, t.y, t.z].map(f32::to_bits)
    }

    /// What it lets through of the light behind: 1 − α + α·t per channel.
    pub fn transmittance(&self) -> Vec3 {
        Vec3::splat(1.0 - self.alpha) + self.alpha * self.transmitted
    }
}

/// A pixel's colour after its layers, and how many layers were merged (0: exact).
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Composite {
    pub color: Vec3,
    pub merged: usize,
}

/// `color` with coverage `alpha` over `under`.
pub fn over(under: Vec3, color: Vec3, alpha: f32) -> Vec3 {
    color * alpha + under * (1.0 - alpha)
}

/// Layer `l` over `under`.
fn layer_over(under: Vec3, l: &Layer) -> Vec3 {
    l.color * l.alpha + under * l.transmittance()
}

/// The farther layers merged into one (None for none): its colour, the weighted mean of
/// theirs (black where none covers anything), and what all of them let through.
fn merge(layers: &[Layer]) -> Option<(Vec3, Vec3)> {
    if layers.is_empty() {
        return None;
    }
    let through: Vec3 = layers.iter().map(Layer::transmittance).product();
    let weight: f32 = layers.iter().map(|l| 1.0 - l.transmittance().min_element()).sum();
    let sum: Vec3 = layers.iter().map(|l| l.color * l.alpha).sum();
    Some((if weight > 0.0 { sum / weight } else { Vec3::ZERO }, through))
}

/// `layers` blended over `under` (the opaque surface's colour, or the background), the
/// `keep` nearest exactly and the rest merged behind them.
pub fn composite(under: Vec3, layers: &[Layer], keep: usize) -> Composite {
    let mut sorted = layers.to_vec();
    sorted.sort_by(|a, b| a.depth.total_cmp(&b.depth).then(a.id.cmp(&b.id)).then_with(|| a.bits().cmp(&b.bits())));
    let split = keep.min(sorted.len());
    let (near, far) = sorted.split_at(split);
    let mut color = under;
    if let Some((c, through)) = merge(far) {
        color = c * (Vec3::ONE - through) + color * through;
    }
    for l in near.iter().rev() {
        color = layer_over(color, l);
    }
    Composite { color, merged: far.len() }
}

/// The most transparent layers `add_glass_layers` adds.
pub const MAX_GLASS_LAYERS: u32 = 256;

/// `percent` % of `scene`'s objects made transparent (BLEND, alpha one half), spread evenly
/// through its list: the benchmark's transparent share.
pub fn make_transparent(scene: &mut Scene, percent: u32) {
    let percent = percent.min(100) as usize;
    for (i, o) in scene.objects.iter_mut().enumerate() {
        // Object i is chosen where the running share crosses a whole number.
        if (i + 1) * percent / 100 > i * percent / 100 {
            o.extras.alpha_mode = AlphaMode::Blend;
            o.extras.base_alpha = 0.5;
        }
    }
}

/// `count` panes of faint tinted glass (alpha 0.08) across the whole view, one behind the
/// other from 1.5 times the near plane's distance to a tenth of the way to the scene's box
/// (or to three times the near plane's distance, where the camera is inside the box), so
/// that nothing opaque stands in front of them: a stress test of transparency, `count`
/// layers on every pixel.
pub fn add_glass_layers(scene: &mut Scene, count: u32, aspect: f32) {
    let camera = scene.camera;
    let forward = camera.forward();
    let (lo, hi) = scene.bounds();
    // The nearest the scene's box comes (0 where the camera is inside it).
    let nearest = (camera.position - camera.position.clamp(lo, hi)).length();
    let first = camera.near * 1.5;
    let last = (nearest * 0.1).max(first * 2.0);
    // Facing the camera: the plane mesh's +Y normal turned to −forward.
    let rotation = Quat::from_rotation_arc(Vec3::Y, -forward);
    let half_tan = (camera.fov_y_deg.to_radians() * 0.5).tan();
    for i in 0..count.min(MAX_GLASS_LAYERS) {
        let t = if count > 1 { i as f32 / (count - 1) as f32 } else { 0.0 };
        let distance = first + (last - first) * t;
        // A square whose inscribed circle holds the view's corners at that distance (the
        // pane's turn about its normal is arbitrary), with room to spare.
        let (half_h, half_w) = (distance * half_tan, distance * half_tan * aspect);
        let half = (half_h * half_h + half_w * half_w).sqrt() * 1.2;
        // Tints around the colour wheel, a golden-ratio step apart.
        let hue = i as f32 * 0.618_034 * std::f32::consts::TAU;
        let third = std::f32::consts::TAU / 3.0;
        let albedo = Vec3::new(hue.cos(), (hue + third).cos(), (hue + 2.0 * third).cos()) * 0.5 + 0.5;
        let mut pane = Object::placed(MeshKind::Plane, Vec3::ZERO, 1.0, Material { albedo, roughness: 0.5, metallic: 0.0 });
        pane.transform = Mat4::from_scale_rotation_translation(Vec3::new(half, 1.0, half), rotation, camera.position + forward * distance);
        pane.extras.alpha_mode = AlphaMode::Blend;
        pane.extras.base_alpha = 0.08;
        pane.extras.double_sided = true;
        scene.objects.push(pane);
    }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layer(depth: f32, id: u32, color: [f32; 3], alpha: f32) -> Layer {
        Layer::blended(depth, id, Vec3::from(color), alpha)
    }

    fn glass() -> [Layer; 3] {
        [layer(0.3, 7, [1.0, 0.1, 0.1], 0.5), layer(0.5, 2, [0.1, 1.0, 0.1], 0.4), layer(0.4, 9, [0.1, 0.1, 1.0], 0.6)]
    }

    #[test]
    fn a_share_of_the_objects_becomes_transparent_evenly() {
        let mut scene = crate::scene::Scene::seed(MeshKind::Sphere, Material::built_in()[0], &crate::lights::LightParams::seed_default())
            .expect("the seed scene");
        make_transparent(&mut scene, 10);
        let blended: Vec<usize> = (0..49).filter(|&i| scene.objects[i].extras.alpha_mode == AlphaMode::Blend).collect();
        assert_eq!(blended, [9, 19, 29, 39]);
        add_glass_layers(&mut scene, 24, 16.0 / 9.0);
        assert_eq!(scene.objects.len(), 49 + 24);
        // Each pane faces the camera and lies in front of the scene.
        let eye = scene.camera.position;
        for pane in &scene.objects[49..] {
            let normal = pane.transform.transform_vector3(Vec3::Y).normalize();
            assert!(normal.dot(scene.camera.forward()) < -0.999);
            assert!((pane.position() - eye).length() < 10.0);
        }
    }

    #[test]
    fn layers_are_blended_back_to_front_whatever_their_order() {
        let wall = Vec3::new(0.8, 0.7, 0.6);
        let [red, green, blue] = glass();
        // Back to front: green (0.5), blue (0.4), red (0.3).
        let expected = over(over(over(wall, green.color, green.alpha), blue.color, blue.alpha), red.color, red.alpha);
        let orders = [[0, 1, 2], [0, 2, 1], [1, 0, 2], [1, 2, 0], [2, 0, 1], [2, 1, 0]];
        for order in orders {
            let layers: Vec<Layer> = order.iter().map(|&i| glass()[i]).collect();
            let c = composite(wall, &layers, 8);
            assert_eq!(c, Composite { color: expected, merged: 0 }, "order {order:?}");
        }
    }

    #[test]
    fn surfaces_at_one_depth_are_ordered_by_id() {
        let under = Vec3::ZERO;
        let a = layer(0.5, 1, [1.0, 0.0, 0.0], 0.5);
        let b = layer(0.5, 2, [0.0, 1.0, 0.0], 0.5);
        let ab = composite(under, &[a, b], 4).color;
        assert_eq!(ab, composite(under, &[b, a], 4).color);
        // The smaller id is in front.
        assert_eq!(ab, over(over(under, b.color, b.alpha), a.color, a.alpha));
        // Of one id too, in an order of their own: the green one, whose colour's bits are the
        // smaller, in front.
        let b = layer(0.5, 1, [0.0, 1.0, 0.0], 0.5);
        let ab = composite(under, &[a, b], 4).color;
        assert_eq!(ab, composite(under, &[b, a], 4).color);
        assert_eq!(ab, over(over(under, a.color, a.alpha), b.color, b.alpha));
    }

    #[test]
    fn opaque_and_empty_layers() {
        let under = Vec3::new(0.2, 0.4, 0.6);
        assert_eq!(composite(under, &[], 4).color, under);
        assert_eq!(composite(under, &[layer(0.1, 0, [1.0, 1.0, 1.0], 0.0)], 4).color, under);
        let solid = composite(under, &[layer(0.1, 0, [0.9, 0.8, 0.7], 1.0)], 4);
        assert_eq!(solid.color, Vec3::new(0.9, 0.8, 0.7));
    }

    #[test]
    fn a_transmitting_layer_tints_what_lies_behind_it() {
        let wall = Vec3::new(0.8, 0.7, 0.6);
        let tinted = Layer { transmitted: Vec3::new(0.9, 0.5, 0.0), ..layer(0.2, 1, [0.1, 0.2, 0.3], 1.0) };
        let c = composite(wall, &[tinted], 4).color;
        assert!((c - (Vec3::new(0.1, 0.2, 0.3) + wall * Vec3::new(0.9, 0.5, 0.0))).abs().max_element() < 1e-6, "{c}");
        // Half covered: half of the wall passes untouched, the other half through the tint.
        let half = Layer { alpha: 0.5, ..tinted };
        let c = composite(wall, &[half], 4).color;
        assert!((c - (Vec3::new(0.05, 0.1, 0.15) + wall * Vec3::new(0.95, 0.75, 0.5))).abs().max_element() < 1e-6, "{c}");
        // Merged, two tints let their product through.
        let other = Layer { depth: 0.3, id: 2, transmitted: Vec3::new(0.5, 1.0, 1.0), color: Vec3::ZERO, ..tinted };
        let merged = composite(Vec3::ONE, &[Layer { color: Vec3::ZERO, ..tinted }, other], 0);
        assert_eq!(merged.merged, 2);
        assert!((merged.color - Vec3::new(0.45, 0.5, 0.0)).abs().max_element() < 1e-6, "{}", merged.color);
    }

    #[test]
    fn layers_past_the_budget_merge_behind_the_nearest_and_are_counted() {
        let wall = Vec3::new(0.8, 0.7, 0.6);
        let layers = glass();
        // One layer merged is that layer: still exact.
        let exact = composite(wall, &layers, 8);
        let one_merged = composite(wall, &layers, 2);
        assert_eq!(one_merged.merged, 1);
        assert!((one_merged.color - exact.color).abs().max_element() < 1e-6);
        // Two merged: counted, order-independent, and the nearest layer still on top.
        let two = composite(wall, &layers, 1);
        assert_eq!(two.merged, 2);
        let reversed: Vec<Layer> = layers.iter().rev().copied().collect();
        assert_eq!(composite(wall, &reversed, 1), two);
        let [red, green, blue] = layers;
        let mean = (green.color * green.alpha + blue.color * blue.alpha) / (green.alpha + blue.alpha);
        let behind = over(wall, mean, 1.0 - (1.0 - green.alpha) * (1.0 - blue.alpha));
        assert!((two.color - over(behind, red.color, red.alpha)).abs().max_element() < 1e-6);
        // What the merged layers cover together is exact: with black glass only the
        // coverage matters, and it equals the exact result.
        let black: Vec<Layer> = layers.iter().map(|l| Layer { color: Vec3::ZERO, ..*l }).collect();
        let exact = composite(wall, &black, 8).color;
        assert!((composite(wall, &black, 0).color - exact).abs().max_element() < 1e-6);
    }
}
