//! The scene's triangles for shadow rays (docs/DESIGN.md#shadow-rays): a bounding volume
//! hierarchy per mesh over its triangles in object space (the bottom levels, built once), and
//! one over the objects' world boxes (the top level, whose leaves are instances: an object's
//! world → object map and its mesh's bottom level). Both are two-wide BVHs built by `obvhs`
//! (PLOC, then reinsertion and leaf collapsing) and flattened into the layout the shaders
//! read (`RayNode`: a node holds both children's boxes, so one read tests both).
//!
//! A shadow ray is a segment from a surface point to a light: it is blocked if any triangle
//! crosses it strictly between the two (any hit ends the search; both faces of a triangle
//! block). `RayScene::occluded` is the CPU model of the shaders' traversal
//! (shadows/shadow_rays.glsl) — the same tests in the same f32 arithmetic — and
//! `WorldTriangles::occluded` the reference it is tested against: every triangle of every
//! object, in world space, no hierarchy.

use crate::geometry::Mesh;
use crate::gpu_types::{RayInstance, RayNode, RayTriangle};
use crate::mesh::MeshKind;
use crate::scene::Scene;
use glam::{Mat4, Vec2, Vec3};
use std::collections::HashMap;
use std::time::Instant;

/// Most primitives a leaf holds (obvhs collapses leaves up to this many where its cost model
/// says they trace faster).
const MAX_LEAF: u32 = 4;

/// Nodes the shaders' traversal keeps to visit (shadow_rays.glsl RAY_STACK): a hierarchy whose
/// `stack_needed` exceeds it cannot be traced there.
pub const RAY_STACK: usize = 64;

/// The shadow rays' hierarchies for a scene, as the GPU reads them.
#[derive(Clone, Debug, Default)]
pub struct RayScene {
    /// Every mesh's bottom level, one after another (children indices are global).
    pub nodes: Vec<RayNode>,
    /// Every mesh's triangles, in the order of their bottom level's leaves.
    pub triangles: Vec<RayTriangle>,
    /// Per triangle, its corners' texture coordinates (v0, v1, v2; what an alpha-masked
    /// object's mask is read at).
    pub uvs: Vec<[f32; 2]>,
    /// The objects with triangles, in the order of the top level's leaves.
    pub instances: Vec<RayInstance>,
    /// The top level over the instances (node 0 its root).
    pub top: Vec<RayNode>,
    /// CPU milliseconds the build took (every bottom level and the top).
    pub build_ms: f64,
}

/// A child of a flattened node: its box, and a node index (count 0) or a leaf's primitives.
#[derive(Clone, Copy)]
struct Child {
    min: Vec3,
    max: Vec3,
    child: u32,
    count: u32,
}

/// A child that no segment enters (a root that is itself a leaf gets one as its sibling): a
/// point at the far corner of the f32 range, which every slab test puts beyond t = 1 or
/// before t = 0 (a box with min > max would not do: the test swaps its slabs' ends).
const EMPTY: Child = Child { min: Vec3::splat(f32::MAX), max: Vec3::splat(f32::MAX), child: 0, count: 0 };

fn node(left: Child, right: Child) -> RayNode {
    RayNode {
        left_min: left.min.to_array(),
        left_child: left.child,
        left_max: left.max.to_array(),
        left_count: left.count,
        right_min: right.min.to_array(),
        right_child: right.child,
        right_max: right.max.to_array(),
        right_count: right.count,
    }
}

/// A box grown by a little more than f32 rounding, so that a segment the box tests would miss
/// by a rounding step still reaches the triangles inside (which decide).
fn padded(min: Vec3, max: Vec3) -> (Vec3, Vec3) {
    let pad = (max - min).max_element() * 1e-5 + min.abs().max(max.abs()).max_element() * 1e-6;
    (min - Vec3::splat(pad), max + Vec3::splat(pad))
}

/// Flatten obvhs's BVH2 into `out` (from `out.len()` on): node i of ours per inner node,
/// leaves' primitives appended to `order` (the caller lays its primitives out in that order,
/// from `first_primitive` on).
fn flatten(bvh: &obvhs::bvh2::Bvh2, out: &mut Vec<RayNode>, order: &mut Vec<u32>, first_primitive: u32) -> u32 {
    let root = out.len() as u32;
    let nodes = &bvh.nodes;
    if nodes.is_empty() {
        out.push(node(EMPTY, EMPTY));
        return root;
    }
    // (obvhs node, our node) pairs still to write; our nodes are made before their children.
    let child_of = |i: usize, out_len: &mut u32, order: &mut Vec<u32>, pending: &mut Vec<(usize, u32)>| -> Child {
        let n = &nodes[i];
        let (min, max) = padded(Vec3::from(n.aabb.min), Vec3::from(n.aabb.max));
        if n.prim_count > 0 {
            let first = first_primitive + order.len() as u32;
            let range = n.first_index as usize..(n.first_index + n.prim_count) as usize;
            order.extend(range.map(|k| bvh.primitive_indices[k]));
            Child { min, max, child: first, count: n.prim_count }
        } else {
            let ours = *out_len;
            *out_len += 1;
            pending.push((i, ours));
            Child { min, max, child: ours, count: 0 }
        }
    };
    let mut out_len = root + 1;
    let mut pending = Vec::new();
    let mut written: Vec<(u32, RayNode)> = Vec::new();
    if nodes[0].prim_count > 0 {
        let leaf = child_of(0, &mut out_len, order, &mut pending);
        written.push((root, node(leaf, EMPTY)));
    } else {
        pending.push((0, root));
    }
    while let Some((i, ours)) = pending.pop() {
        let first = nodes[i].first_index as usize;
        let left = child_of(first, &mut out_len, order, &mut pending);
        let right = child_of(first + 1, &mut out_len, order, &mut pending);
        written.push((ours, node(left, right)));
    }
    out.resize(out_len as usize, node(EMPTY, EMPTY));
    for (i, n) in written {
        out[i as usize] = n;
    }
    root
}

/// A mesh's triangles in object space (obvhs's form).
fn mesh_triangles(mesh: &Mesh) -> Vec<obvhs::triangle::Triangle> {
    let p = |i: u32| glam::Vec3A::from_array(mesh.vertices[i as usize].position);
    mesh.indices.chunks_exact(3).map(|t| obvhs::triangle::Triangle { v0: p(t[0]), v1: p(t[1]), v2: p(t[2]) }).collect()
}

/// A world box as obvhs bounds it.
struct WorldBox(obvhs::aabb::Aabb);

impl obvhs::Boundable for WorldBox {
    fn aabb(&self) -> obvhs::aabb::Aabb {
        self.0
    }
}

/// The world box of a box in object space under `m`.
fn transformed_box(m: &Mat4, min: Vec3, max: Vec3) -> (Vec3, Vec3) {
    (0..8).fold((Vec3::splat(f32::MAX), Vec3::splat(f32::MIN)), |(lo, hi), k| {
        let corner = Vec3::new(
            if k & 1 == 0 { min.x } else { max.x },
            if k & 2 == 0 { min.y } else { max.y },
            if k & 4 == 0 { min.z } else { max.z },
        );
        let w = m.transform_point3(corner);
        (lo.min(w), hi.max(w))
    })
}

/// The rows of the affine map world → object space of an object placed by `transform`.
fn to_object_rows(transform: &Mat4) -> [[f32; 4]; 3] {
    let inv = transform.inverse();
    let row = |r: usize| [inv.col(0)[r], inv.col(1)[r], inv.col(2)[r], inv.col(3)[r]];
    [row(0), row(1), row(2)]
}

fn build_params() -> obvhs::BvhBuildParams {
    obvhs::BvhBuildParams { max_prims_per_leaf: MAX_LEAF, ..obvhs::BvhBuildParams::fast_build() }
}

impl RayScene {
    /// The hierarchies of `scene`'s objects: a bottom level per mesh (each built once, however
    /// many objects draw it), the top level over the objects with triangles.
    pub fn build(scene: &Scene) -> RayScene {
        let start = Instant::now();
        let mut rays = RayScene::default();
        let mut duration = std::time::Duration::ZERO;
        // Per mesh kind: its root and object-space box (None: no triangles).
        let mut roots = Vec::new();
        for kind in scene.mesh_kinds() {
            let Some(mesh) = scene.mesh(kind) else { continue };
            let tris = mesh_triangles(&mesh);
            if tris.is_empty() {
                roots.push((kind, None));
                continue;
            }
            let bvh = obvhs::bvh2::builder::build_bvh2_from_tris(&tris, build_params(), &mut duration);
            let mut order = Vec::new();
            let first = rays.triangles.len() as u32;
            let root = flatten(&bvh, &mut rays.nodes, &mut order, first);
            let uv = |i: u32| mesh.vertices[i as usize].uv;
            rays.uvs.extend(order.iter().flat_map(|&t| mesh.indices[3 * t as usize..3 * t as usize + 3].iter().map(|&i| uv(i))));
            rays.triangles.extend(order.iter().map(|&t| {
                let tri = &tris[t as usize];
                let v0 = Vec3::from(tri.v0);
                RayTriangle {
                    v0: v0.to_array(),
                    source: t,
                    e1: (Vec3::from(tri.v1) - v0).to_array(),
                    e2: (Vec3::from(tri.v2) - v0).to_array(),
                    ..RayTriangle::default()
                }
            }));
            let b = &bvh.nodes[0].aabb;
            roots.push((kind, Some((root, Vec3::from(b.min), Vec3::from(b.max)))));
        }
        let mut placed = Vec::new();
        let mut boxes = Vec::new();
        // Each kind's root by a map: a scene may hold as many meshes as objects.
        let roots: HashMap<MeshKind, Option<(u32, Vec3, Vec3)>> = roots.into_iter().collect();
        for (i, o) in scene.objects.iter().enumerate() {
            let Some(&Some((root, min, max))) = roots.get(&o.mesh) else { continue };
            let (lo, hi) = transformed_box(&o.transform, min, max);
            boxes.push(WorldBox(obvhs::aabb::Aabb { min: lo.into(), max: hi.into() }));
            placed.push(RayInstance { to_object: to_object_rows(&o.transform), root, object: i as u32, ..RayInstance::default() });
        }
        let mut order = Vec::new();
        if boxes.is_empty() {
            rays.top.push(node(EMPTY, EMPTY));
        } else {
            let bvh = obvhs::bvh2::builder::build_bvh2(&boxes, build_params(), &mut duration);
            flatten(&bvh, &mut rays.top, &mut order, 0);
        }
        rays.instances = order.iter().map(|&k| placed[k as usize]).collect();
        rays.build_ms = start.elapsed().as_secs_f64() * 1e3;
        rays
    }

    /// Bytes the GPU holds for it.
    pub fn bytes(&self) -> u64 {
        let size = |n: usize, each: usize| (n * each) as u64;
        size(self.nodes.len() + self.top.len(), size_of::<RayNode>())
            + size(self.triangles.len(), size_of::<RayTriangle>())
            + size(self.uvs.len(), 8)
            + size(self.instances.len(), size_of::<RayInstance>())
    }

    /// Most entries the traversal keeps on its one stack: the top level's pending nodes (one
    /// per inner node on its deepest path, and one more), the instances of the two leaves of
    /// one top node, the way back from a mesh, and that mesh's pending nodes (one per inner
    /// node on its deepest path).
    pub fn stack_needed(&self) -> usize {
        fn deepest(nodes: &[RayNode], root: u32) -> usize {
            if nodes.is_empty() {
                return 0;
            }
            let mut most = 0;
            let mut stack = vec![(root, 0usize)];
            while let Some((n, depth)) = stack.pop() {
                most = most.max(depth);
                for c in children(&nodes[n as usize]) {
                    if c.count == 0 && c.min != EMPTY.min {
                        stack.push((c.child, depth + 1));
                    }
                }
            }
            most
        }
        if self.top.is_empty() {
            return 0;
        }
        let top_leaves = self.top.iter().map(|n| (n.left_count + n.right_count) as usize).max().unwrap_or(0);
        let mesh = self.instances.iter().map(|i| deepest(&self.nodes, i.root)).max().unwrap_or(0);
        deepest(&self.top, 0) + 1 + top_leaves + 1 + mesh
    }

    /// Whether a triangle crosses the segment from `origin` to `target` strictly between them:
    /// the shaders' traversal (shadows/shadow_rays.glsl), step for step — both levels in one
    /// loop over one stack, whose deepest use is returned too (`stack_needed` bounds it).
    pub fn occluded(&self, origin: Vec3, target: Vec3) -> bool {
        self.traverse(origin, target).0
    }

    /// `occluded`, and the most entries its stack held.
    pub fn traverse(&self, origin: Vec3, target: Vec3) -> (bool, usize) {
        if self.top.is_empty() {
            return (false, 0);
        }
        let world_d = target - origin;
        let world = Segment::new(origin, world_d);
        let (mut seg, mut d) = (world.clone(), world_d);
        let mut stack: Vec<Entry> = Vec::new();
        let mut most = 0;
        let mut entry = Entry::Top(0);
        loop {
            most = most.max(stack.len());
            match entry {
                Entry::Enter(i) => {
                    // Into the instance's object space, the way back on the stack.
                    let inst = &self.instances[i as usize];
                    let rows = inst.to_object.map(glam::Vec4::from_array);
                    let o = Vec3::new(
                        rows[0].truncate().dot(origin) + rows[0].w,
                        rows[1].truncate().dot(origin) + rows[1].w,
                        rows[2].truncate().dot(origin) + rows[2].w,
                    );
                    d = Vec3::new(rows[0].truncate().dot(world_d), rows[1].truncate().dot(world_d), rows[2].truncate().dot(world_d));
                    seg = Segment::new(o, d);
                    stack.push(Entry::Leave);
                    entry = Entry::Mesh(inst.root);
                }
                Entry::Leave => {
                    (seg, d) = (world.clone(), world_d);
                    match stack.pop() {
                        Some(next) => entry = next,
                        None => return (false, most),
                    }
                }
                Entry::Top(n) => {
                    // The children to visit on the stack, above them the instances of the
                    // leaves entered (so these are entered first).
                    let cs = children(&self.top[n as usize]).map(|c| (seg.enters(c.min, c.max), c));
                    stack.extend(cs.iter().filter(|(e, c)| *e && c.count == 0).map(|(_, c)| Entry::Top(c.child)));
                    for (_, c) in cs.iter().filter(|(e, c)| *e && c.count != 0) {
                        stack.extend((c.child..c.child + c.count).map(Entry::Enter));
                    }
                    most = most.max(stack.len());
                    match stack.pop() {
                        Some(next) => entry = next,
                        None => return (false, most),
                    }
                }
                Entry::Mesh(n) => {
                    let mut next = Vec::new();
                    for c in children(&self.nodes[n as usize]) {
                        if !seg.enters(c.min, c.max) {
                            continue;
                        }
                        if c.count == 0 {
                            next.push(c.child);
                        } else {
                            let tris = &self.triangles[c.child as usize..(c.child + c.count) as usize];
                            let o = seg.origin;
                            if tris.iter().any(|t| segment_crosses(o, d, Vec3::from(t.v0), Vec3::from(t.e1), Vec3::from(t.e2))) {
                                return (true, most);
                            }
                        }
                    }
                    // Both entered: the right kept, the left visited next.
                    if let [left, right] = next[..] {
                        stack.push(Entry::Mesh(right));
                        most = most.max(stack.len());
                        entry = Entry::Mesh(left);
                    } else if let [only] = next[..] {
                        entry = Entry::Mesh(only);
                    } else {
                        // A mesh's stack always holds its way back below its nodes.
                        entry = stack.pop().expect("the way back from a mesh");
                    }
                }
            }
        }
    }
}

/// A traversal stack entry (shadow_rays.glsl: the entry's top two bits).
#[derive(Clone, Copy, Debug)]
enum Entry {
    /// A node of the top level.
    Top(u32),
    /// A node of a mesh's hierarchy.
    Mesh(u32),
    /// An instance to enter.
    Enter(u32),
    /// The end of an instance: back to the world segment.
    Leave,
}

fn children(n: &RayNode) -> [Child; 2] {
    [
        Child { min: Vec3::from(n.left_min), max: Vec3::from(n.left_max), child: n.left_child, count: n.left_count },
        Child { min: Vec3::from(n.right_min), max: Vec3::from(n.right_max), child: n.right_child, count: n.right_count },
    ]
}

/// A segment `origin + t·d`, t in [0, 1], as the box test takes it.
#[derive(Clone)]
struct Segment {
    origin: Vec3,
    inv: Vec3,
}

/// Smallest |direction| the box test divides by (a zero component would give 0·∞).
const MIN_DIRECTION: f32 = 1e-30;

impl Segment {
    fn new(origin: Vec3, d: Vec3) -> Segment {
        let tiny = |x: f32| if x < 0.0 { -MIN_DIRECTION } else { MIN_DIRECTION };
        let safe = |x: f32| if x.abs() < MIN_DIRECTION { tiny(x) } else { x };
        Segment { origin, inv: Vec3::new(1.0 / safe(d.x), 1.0 / safe(d.y), 1.0 / safe(d.z)) }
    }

    /// Whether the segment meets the box.
    fn enters(&self, min: Vec3, max: Vec3) -> bool {
        let t0 = (min - self.origin) * self.inv;
        let t1 = (max - self.origin) * self.inv;
        let near = t0.min(t1).max_element().max(0.0);
        let far = t0.max(t1).min_element().min(1.0);
        near <= far
    }
}

/// Whether the triangle (`v0`, edges `e1`, `e2`) crosses the segment `o + t·d` at some
/// 0 < t < 1 (Möller–Trumbore; either face; a triangle edge-on to the segment never).
pub fn segment_crosses(o: Vec3, d: Vec3, v0: Vec3, e1: Vec3, e2: Vec3) -> bool {
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det == 0.0 {
        return false;
    }
    let inv_det = 1.0 / det;
    let s = o - v0;
    let u = s.dot(p) * inv_det;
    if !(0.0..=1.0).contains(&u) {
        return false;
    }
    let q = s.cross(e1);
    let v = d.dot(q) * inv_det;
    if v < 0.0 || u + v > 1.0 {
        return false;
    }
    let t = e2.dot(q) * inv_det;
    t > 0.0 && t < 1.0
}

/// Every triangle of every object of a scene in world space: the reference shadow rays are
/// tested against (no hierarchy, nothing skipped; an alpha-masked object's triangles block
/// only where its mask keeps the point, by `alpha_mask::kept`, the shaders' twin).
pub struct WorldTriangles<'a> {
    scene: &'a Scene,
    /// (v0, e1, e2) per triangle.
    triangles: Vec<[Vec3; 3]>,
    /// Per triangle: its object and its corners' texture coordinates.
    sources: Vec<(u32, [Vec2; 3])>,
    /// Per triangle: its box (min, max), widened by a relative hair for rounding, and the
    /// length of its two edges from v0, added.
    boxes: Vec<(Vec3, Vec3, f32)>,
}

/// Where a segment `o + t·d` meets a triangle's plane: the barycentric weights of v1 and v2,
/// and t (None where the segment lies parallel to the plane, or so nearly that the
/// determinant is at most `min_det` in magnitude).
fn crossing(o: Vec3, d: Vec3, [v0, e1, e2]: [Vec3; 3], min_det: f32) -> Option<(f32, f32, f32)> {
    let p = d.cross(e2);
    let det = e1.dot(p);
    if det.abs() <= min_det || det.is_nan() {
        return None;
    }
    let s = o - v0;
    let q = s.cross(e1);
    Some((s.dot(p) / det, d.dot(q) / det, e2.dot(q) / det))
}

impl<'a> WorldTriangles<'a> {
    pub fn new(scene: &'a Scene) -> WorldTriangles<'a> {
        // Each mesh built (or cloned) once, however many objects draw it.
        let meshes: HashMap<MeshKind, Option<Mesh>> = scene.mesh_kinds().into_iter().map(|kind| (kind, scene.mesh(kind))).collect();
        let (mut triangles, mut sources) = (Vec::new(), Vec::new());
        for (k, o) in scene.objects.iter().enumerate() {
            let Some(mesh) = &meshes[&o.mesh] else { continue };
            let p = |i: u32| o.transform.transform_point3(Vec3::from(mesh.vertices[i as usize].position));
            let uv = |i: u32| Vec2::from(mesh.vertices[i as usize].uv);
            for t in mesh.indices.chunks_exact(3) {
                let v0 = p(t[0]);
                triangles.push([v0, p(t[1]) - v0, p(t[2]) - v0]);
                sources.push((k as u32, [uv(t[0]), uv(t[1]), uv(t[2])]));
            }
        }
        let boxes = triangles
            .iter()
            .map(|&[v0, e1, e2]| {
                let (a, b) = (v0 + e1, v0 + e2);
                let (min, max) = (v0.min(a).min(b), v0.max(a).max(b));
                let hair = 1e-5 * min.abs().max(max.abs()).max_element();
                (min - hair, max + hair, e1.length() + e2.length())
            })
            .collect();
        WorldTriangles { scene, triangles, sources, boxes }
    }

    /// Whether triangle `i` lies clear of the segment's box: no point of the segment (or of
    /// its line within `dist` beyond its ends) comes within `bary` (barycentric units) of the
    /// triangle, nor within `dist` of its plane's part near it — the cheap test that lets every
    /// test below skip most triangles. Conservative: the margins grow with the triangle's size,
    /// and both boxes are widened by a relative hair for rounding.
    #[inline]
    fn clear_of(&self, i: usize, (lo, hi): (Vec3, Vec3), bary: f32, dist: f32) -> bool {
        let (min, max, span) = self.boxes[i];
        let margin = dist + 2.0 * bary * span;
        (lo - margin).cmpgt(max).any() || (hi + margin).cmplt(min).any()
    }

    /// A segment's box, widened by a relative hair for rounding.
    fn segment_box(origin: Vec3, target: Vec3) -> (Vec3, Vec3) {
        let (lo, hi) = (origin.min(target), origin.max(target));
        let hair = 1e-5 * lo.abs().max(hi.abs()).max_element();
        (lo - hair, hi + hair)
    }

    /// Whether triangle `i`'s point at barycentric weights (u, v) of its second and third
    /// corners is there (its object's alpha mask keeps it).
    fn kept(&self, i: usize, u: f32, v: f32) -> bool {
        let (object, [uv0, uv1, uv2]) = self.sources[i];
        let o = &self.scene.objects[object as usize];
        !o.extras.masked() || crate::alpha_mask::kept(o, &self.scene.textures, uv0 * (1.0 - u - v) + uv1 * u + uv2 * v)
    }

    /// Whether any triangle crosses the segment from `origin` to `target` strictly between
    /// them where it is there.
    pub fn occluded(&self, origin: Vec3, target: Vec3) -> bool {
        let d = target - origin;
        let segment = Self::segment_box(origin, target);
        self.triangles.iter().enumerate().any(|(i, &[v0, e1, e2])| {
            !self.clear_of(i, segment, 0.0, 0.0)
                && segment_crosses(origin, d, v0, e1, e2)
                && crossing(origin, d, [v0, e1, e2], 0.0).is_some_and(|(u, v, _)| self.kept(i, u, v))
        })
    }

    /// The nearest point the ray `o + t·d` (t > 0) meets: t, the triangle's unit normal (facing
    /// against `d`) and its object.
    pub fn first_hit(&self, o: Vec3, d: Vec3) -> Option<(f32, Vec3, u32)> {
        let mut best: Option<(f32, Vec3, u32)> = None;
        for (i, &tri) in self.triangles.iter().enumerate() {
            let Some((u, v, t)) = crossing(o, d, tri, 0.0) else { continue };
            let inside = u >= 0.0 && v >= 0.0 && u + v <= 1.0 && t > 0.0;
            if inside && best.is_none_or(|(b, _, _)| t < b) && self.kept(i, u, v) {
                let n = tri[1].cross(tri[2]).normalize();
                best = Some((t, if n.dot(d) > 0.0 { -n } else { n }, self.sources[i].0));
            }
        }
        best
    }

    /// Whether every triangle's answer for the segment holds under rounding: a triangle it
    /// misses, it misses by more than `bary` (barycentric units) beside an edge or by more than
    /// `dist` (world units) before or after its ends; one it crosses, it crosses by both, and
    /// where its object is masked, the alpha there is more than 1/64 from the cutoff. (The
    /// tests leave segments within a hair of an edge, an end or a mask's edge out.)
    /// A triangle clear of the segment's box by those margins is missed, surely.
    pub fn sure(&self, origin: Vec3, target: Vec3, bary: f32, dist: f32) -> bool {
        let d = target - origin;
        let length = d.length();
        let segment = Self::segment_box(origin, target);
        self.triangles.iter().enumerate().all(|(i, &tri)| {
            if self.clear_of(i, segment, bary, dist) {
                return true;
            }
            let Some((u, v, t)) = crossing(origin, d, tri, 1e-20) else {
                // Edge-on: the segment lies in the triangle's plane or parallel to it.
                let n = tri[1].cross(tri[2]).normalize_or_zero();
                return (origin - tri[0]).dot(n).abs() > dist;
            };
            let inside = u.min(v).min(1.0 - u - v);
            let within = t.min(1.0 - t) * length;
            if inside >= 0.0 && within >= 0.0 {
                inside > bary && within > dist && self.alpha_clear(i, u, v)
            } else {
                inside < -bary || within < -dist
            }
        })
    }

    /// Whether triangle `i`'s alpha at (u, v), if its object is masked, is clear of the cutoff.
    fn alpha_clear(&self, i: usize, u: f32, v: f32) -> bool {
        let (object, [uv0, uv1, uv2]) = self.sources[i];
        let o = &self.scene.objects[object as usize];
        let Some(cutoff) = o.extras.alpha_mode.cutoff() else { return true };
        let alpha = match o.textures.base_color.and_then(|t| self.scene.textures.get(t as usize)) {
            Some(t) => {
                let uv = o.extras.uv_transform.transform_point2(uv0 * (1.0 - u - v) + uv1 * u + uv2 * v);
                o.extras.base_alpha * crate::alpha_mask::texture_alpha(t, uv)
            }
            None => o.extras.base_alpha,
        };
        (alpha - cutoff).abs() > 1.0 / 64.0
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::material::Material;
    use crate::mesh::MeshKind;
    use crate::scene::Object;
    use rand::{Rng, SeedableRng};

    fn grey() -> Material {
        Material { albedo: Vec3::splat(0.5), roughness: 0.5, metallic: 0.0 }
    }

    /// Objects of every built-in mesh, rotated, scaled unevenly and overlapping, in a room.
    fn cluttered_scene(seed: u64) -> Scene {
        let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(seed);
        let mut objects =
            vec![Object { transform: Mat4::from_scale(Vec3::splat(8.0)), ..Object::placed(MeshKind::Room, Vec3::ZERO, 1.0, grey()) }];
        for k in 0..24 {
            let kind = MeshKind::ALL[k % MeshKind::ALL.len()];
            if kind == MeshKind::Room {
                continue;
            }
            let at = Vec3::new(rng.random_range(-6.0..6.0), rng.random_range(-6.0..6.0), rng.random_range(-6.0..6.0));
            let rotation = glam::Quat::from_euler(glam::EulerRot::XYZ, rng.random_range(0.0..6.3), rng.random_range(0.0..6.3), 0.3);
            let scale = Vec3::new(rng.random_range(0.3..2.0), rng.random_range(0.3..2.0), rng.random_range(0.3..2.0));
            let transform = Mat4::from_scale_rotation_translation(scale, rotation, at);
            objects.push(Object { transform, ..Object::placed(kind, Vec3::ZERO, 1.0, grey()) });
        }
        Scene::new(objects, Vec::new(), crate::camera::Camera::seed())
    }

    #[test]
    fn the_hierarchy_blocks_exactly_the_segments_some_triangle_crosses() {
        for seed in 0..3 {
            let scene = cluttered_scene(seed);
            let rays = RayScene::build(&scene);
            let world = WorldTriangles::new(&scene);
            let mut rng = rand_chacha::ChaCha8Rng::seed_from_u64(100 + seed);
            let (mut blocked, mut checked, mut deepest) = (0, 0, 0);
            for _ in 0..2000 {
                let mut p = || Vec3::new(rng.random_range(-7.9..7.9), rng.random_range(-7.9..7.9), rng.random_range(-7.9..7.9));
                let (origin, target) = (p(), p());
                // A segment within a rounding step of an edge or an end may go either way.
                if !world.sure(origin, target, 1e-4, 1e-4) {
                    continue;
                }
                let expected = world.occluded(origin, target);
                let (occluded, stack) = rays.traverse(origin, target);
                assert_eq!(occluded, expected, "seed {seed}: {origin} -> {target}");
                assert!(stack <= rays.stack_needed(), "seed {seed}: {stack} entries, bound {}", rays.stack_needed());
                deepest = deepest.max(stack);
                blocked += usize::from(expected);
                checked += 1;
            }
            // Both answers are common, so neither could pass by always being given; the stack
            // holds a mesh's nodes above the top level's.
            assert!(checked > 1500 && blocked > checked / 10 && blocked < checked * 9 / 10, "{blocked} of {checked} blocked");
            assert!(deepest > 4, "{deepest}");
        }
    }

    #[test]
    fn a_segment_ends_before_the_triangles_at_its_ends() {
        // A floor at y = 0: a segment from above it to a point on it is not blocked; one that
        // goes through it is.
        let floor =
            Object { transform: Mat4::from_scale(Vec3::new(5.0, 1.0, 5.0)), ..Object::placed(MeshKind::Plane, Vec3::ZERO, 1.0, grey()) };
        let scene = Scene::new(vec![floor], Vec::new(), crate::camera::Camera::seed());
        let rays = RayScene::build(&scene);
        assert!(!rays.occluded(Vec3::new(0.3, 2.0, 0.1), Vec3::new(0.5, 0.0, 0.2)));
        assert!(rays.occluded(Vec3::new(0.3, 2.0, 0.1), Vec3::new(0.5, -1.0, 0.2)));
        assert!(!rays.occluded(Vec3::new(0.3, 2.0, 0.1), Vec3::new(9.0, -1.0, 0.2)), "passes beside the floor");
    }

    #[test]
    fn one_object_of_one_triangle_and_a_scene_without_triangles_trace() {
        let empty = Scene::new(Vec::new(), Vec::new(), crate::camera::Camera::seed());
        assert!(!RayScene::build(&empty).occluded(Vec3::ZERO, Vec3::ONE));
        let mut one = Scene::new(Vec::new(), Vec::new(), crate::camera::Camera::seed());
        one.meshes.push(Mesh {
            vertices: [[-1.0, 0.0, -1.0], [1.0, 0.0, -1.0], [0.0, 0.0, 1.0]]
                .map(|p| crate::geometry::Vertex { position: p, normal: [0.0, 1.0, 0.0], uv: [0.0; 2], tangent: [0.0; 4] })
                .to_vec(),
            indices: vec![0, 1, 2],
        });
        one.objects.push(Object::placed(MeshKind::Loaded(0), Vec3::ZERO, 1.0, grey()));
        let rays = RayScene::build(&one);
        assert_eq!(rays.triangles.len(), 1);
        assert!(rays.occluded(Vec3::new(0.0, 1.0, 0.0), Vec3::new(0.0, -1.0, 0.0)));
        assert!(!rays.occluded(Vec3::new(3.0, 1.0, 0.0), Vec3::new(3.0, -1.0, 0.0)));
    }

    #[test]
    fn each_mesh_is_built_once_however_many_objects_draw_it() {
        let scene = cluttered_scene(7);
        let rays = RayScene::build(&scene);
        let kinds = scene.mesh_kinds();
        let expected: usize = kinds.iter().map(|&k| scene.mesh(k).unwrap().indices.len() / 3).sum();
        assert_eq!(rays.triangles.len(), expected);
        assert_eq!(rays.instances.len(), scene.objects.len());
        assert!((1..=RAY_STACK).contains(&rays.stack_needed()), "{}", rays.stack_needed());
        let mut objects: Vec<u32> = rays.instances.iter().map(|i| i.object).collect();
        objects.sort_unstable();
        assert_eq!(objects, (0..scene.objects.len() as u32).collect::<Vec<_>>());
    }
}
