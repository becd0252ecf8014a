//! Transparency's per-pixel rule (glTF `alphaMode: BLEND`), the reference every transparent
//! path is held to: the transparent layers in front of a pixel's opaque surface are blended
//! over it back to front in linear light, each `colour · α + under · (1 − α)`.
//!
//! The order is the layers' depth, ties broken by their ids (object and triangle), so the
//! result does not depend on the order in which the surfaces were listed or drawn. A pixel
//! keeps at most `keep` layers exactly, the nearest; the farther ones are merged into one
//! layer behind those, whose coverage is `1 − Π(1 − αᵢ)` (what they cover together) and whose
//! colour is their α-weighted mean. The merge is order-independent too, exact where it holds
//! one layer and an approximation beyond, so a renderer counts the pixels it merged.

use glam::Vec3;

/// One transparent surface in front of a pixel: its depth (nearer is smaller), an id that
/// orders surfaces at the same depth, its lit colour (linear) and its coverage.
#[derive(Clone, Copy, Debug, PartialEq)]
pub struct Layer {
    pub depth: f32,
    pub id: u32,
    pub color: Vec3,
    pub alpha: f32,
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

/// The farther layers merged into one (None for none): coverage `1 − Π(1 − αᵢ)`, colour the
/// α-weighted mean (black where none covers anything).
fn merge(layers: &[Layer]) -> Option<(Vec3, f32)> {
    if layers.is_empty() {
        return None;
    }
    let uncovered: f32 = layers.iter().map(|l| 1.0 - l.alpha).product();
    let weight: f32 = layers.iter().map(|l| l.alpha).sum();
    let sum: Vec3 = layers.iter().map(|l| l.color * l.alpha).sum();
    Some((if weight > 0.0 { sum / weight } else { Vec3::ZERO }, 1.0 - uncovered))
}

/// `layers` blended over `under` (the opaque surface's colour, or the background), the
/// `keep` nearest exactly and the rest merged behind them.
pub fn composite(under: Vec3, layers: &[Layer], keep: usize) -> Composite {
    let mut sorted = layers.to_vec();
    sorted.sort_by(|a, b| a.depth.total_cmp(&b.depth).then(a.id.cmp(&b.id)));
    let split = keep.min(sorted.len());
    let (near, far) = sorted.split_at(split);
    let mut color = under;
    if let Some((c, a)) = merge(far) {
        color = over(color, c, a);
    }
    for l in near.iter().rev() {
        color = over(color, l.color, l.alpha);
    }
    Composite { color, merged: far.len() }
}

#[cfg(test)]
mod tests {
    use super::*;

    fn layer(depth: f32, id: u32, color: [f32; 3], alpha: f32) -> Layer {
        Layer { depth, id, color: Vec3::from(color), alpha }
    }

    fn glass() -> [Layer; 3] {
        [layer(0.3, 7, [1.0, 0.1, 0.1], 0.5), layer(0.5, 2, [0.1, 1.0, 0.1], 0.4), layer(0.4, 9, [0.1, 0.1, 1.0], 0.6)]
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
