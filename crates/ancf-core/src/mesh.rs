//! Structured hexahedral meshes of fluid regions.
//!
//! A mesh is a structured grid of `n_x × n_y × n_z` ANCF bricks in a parametric box
//! (u, v, w). The reference (stress-free, curved) configuration is the image of that
//! box under a geometric map X(u, v, w); every node stores X and the gradients
//! ∂X/∂u, ∂X/∂v, ∂X/∂w (12 coordinates), and neighbouring elements share all 12, so
//! positions and gradients are continuous across element faces (seed 000 §8).
//!
//! Node gradients are central differences of the map with a small step. Where the map
//! is not differentiable (the tangency of an ellipsoidal head with the cylindrical shell,
//! where ∂x/∂ρ is infinite) the small-step gradient blows up (detected when it is more
//! than twice the secant slope over half an element). Such a node lies on the edge of the
//! map (the head rim, where the wall meets the shell), and there its gradient is the slope
//! that makes the element edge, a cubic Hermite curve between the node and its neighbour,
//! the least-squares fit of the map along that edge (the neighbour's slope given); an
//! interior singular node keeps the secant slope. (Along an edge the brick interpolates
//! exactly this cubic: its nodal positions and the two slopes along the edge.) The
//! least-squares edge leaves the tank car's meshes an eighth to a tenth of the volume error
//! of the secant slope (2×2×2: −0.17 % against −1.3 %; 6×4×2: −0.056 % against −0.58 %), and
//! the liquid at rest no longer creeps into a gap at the rim (docs/validation.md, "A stable
//! rest state"). The mesh's own volume therefore differs slightly from the exact volume of
//! the region; [`FluidMesh::exact_volume`] keeps the latter so tests can measure the difference.
//!
//! **Mirror symmetry.** A region symmetric about the plane y = 0 (or x = 0) gets a mesh that is
//! symmetric to the last bit: the nodes on one side are the mirror images of those on the other
//! ([`Mirror`]). The differences above are not: the map's two sides
//! round differently, and at the head rim, where √(1 − ρ²) amplifies a rounding of ρ² into
//! 1e-8 m, the cross-section gradients of mirror nodes differed by 1.7e-5 (tank car, 6×4×2):
//! an asymmetric seed seven decades above rounding that a growing antisymmetric mode of the
//! sloshing state raised to a lateral load of 1.3 kN in the ECP study (docs/validation.md,
//! "The ECP scenes' lateral channels").
//!
//! All shapes are given in the **tank frame**: x along the tank axis (forward), y to the
//! left, z up, origin at the tank centre (see `docs/frames.md`).

use crate::error::{Result, check_positive, check_range, invalid};
use crate::shape::COORDS_PER_NODE;

/// A face of the reference cube of an element.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum Face {
    /// ξ = −1.
    XMin,
    /// ξ = +1.
    XMax,
    /// η = −1.
    YMin,
    /// η = +1.
    YMax,
    /// ζ = −1.
    ZMin,
    /// ζ = +1.
    ZMax,
}

/// What lies beyond a boundary face.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Hash)]
pub enum BoundaryKind {
    /// The face lies on a tank wall (candidate for fluid–wall contact).
    Wall,
    /// The face is the initial free surface.
    FreeSurface,
}

/// A boundary face of the mesh.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct BoundaryFace {
    /// Element index.
    pub element: usize,
    /// Which face of the element.
    pub face: Face,
    /// Wall or free surface.
    pub kind: BoundaryKind,
}

/// A structured ANCF fluid mesh.
#[derive(Debug, Clone)]
pub struct FluidMesh {
    /// Reference nodal coordinates [X, ∂X/∂u, ∂X/∂v, ∂X/∂w] of each node.
    pub nodes: Vec<[f64; COORDS_PER_NODE]>,
    /// Element connectivity, node order A..H (see [`crate::shape::NODE_SIGNS`]).
    pub elements: Vec<[usize; 8]>,
    /// Straight-configuration edge lengths of each element (parametric units).
    pub lengths: Vec<[f64; 3]>,
    /// Element counts (n_x, n_y, n_z) along length, width and height.
    pub counts: [usize; 3],
    /// Boundary faces.
    pub boundary: Vec<BoundaryFace>,
    /// Exact volume of the region the mesh approximates (m³).
    pub exact_volume: f64,
    /// Height of the initial free surface in the tank frame (m).
    pub free_surface_z: f64,
    /// Short description of the shape.
    pub kind: String,
}

impl FluidMesh {
    /// Depth of the liquid in the reference configuration: the free surface's height above the
    /// lowest node (m).
    pub fn liquid_depth(&self) -> f64 {
        self.free_surface_z - self.nodes.iter().map(|n| n[2]).fold(f64::INFINITY, f64::min)
    }

    /// Number of nodes.
    pub fn n_nodes(&self) -> usize {
        self.nodes.len()
    }
    /// Number of elements.
    pub fn n_elements(&self) -> usize {
        self.elements.len()
    }
    /// Number of generalized coordinates (12 per node).
    pub fn n_coords(&self) -> usize {
        COORDS_PER_NODE * self.nodes.len()
    }
    /// Reference coordinates as one flat vector (node-major, 12 per node).
    pub fn reference_coordinates(&self) -> Vec<f64> {
        self.nodes.iter().flatten().copied().collect()
    }
}

/// The fill of a tank mesh, a liquid volume fraction in (0, 0.97]: above 0.97 the elements at
/// the free surface's edge degenerate (Python's `railslosh.limits.FILL` keeps 0.03 to 0.97,
/// below which the bottom row is a sliver).
pub fn check_fill(fill: f64) -> Result<()> {
    if !(fill.is_finite() && fill > 0.0 && fill <= 0.97) {
        return Err(invalid("fill", fill, "a volume fraction in (0, 0.97]"));
    }
    Ok(())
}

fn check_count(field: &str, n: usize) -> Result<()> {
    if (1..=10_000).contains(&n) { Ok(()) } else { Err(invalid(field, n, "an integer in [1, 10000]")) }
}

/// Node positions along one parametric direction: `n` elements over `[0, len]`,
/// element lengths in geometric progression with last/first ratio `grading`.
fn graded_nodes(n: usize, len: f64, grading: f64) -> Vec<f64> {
    let q = if n > 1 { grading.powf(1.0 / (n as f64 - 1.0)) } else { 1.0 };
    let mut w: Vec<f64> = (0..n).map(|i| q.powi(i as i32)).collect();
    let total: f64 = w.iter().sum();
    w.iter_mut().for_each(|x| *x *= len / total);
    let mut out = vec![0.0];
    for x in w {
        out.push(out.last().unwrap() + x);
    }
    out[n] = len;
    out
}

/// Build a structured mesh from parametric node positions and a map.
fn structured<M: Fn([f64; 3]) -> [f64; 3]>(
    u: &[f64],
    v: &[f64],
    w: &[f64],
    map: M,
    mirror: Mirror,
    top_is_free_surface: bool,
    exact_volume: f64,
    free_surface_z: f64,
    kind: String,
) -> FluidMesh {
    let (nx, ny, nz) = (u.len() - 1, v.len() - 1, w.len() - 1);
    let axes = [u, v, w];
    let mut nodes = Vec::with_capacity(u.len() * v.len() * w.len());
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                let idx = [i, j, k];
                let p = [u[i], v[j], w[k]];
                let x0 = map(p);
                let mut node = [0.0; COORDS_PER_NODE];
                node[..3].copy_from_slice(&x0);
                for d in 0..3 {
                    let g = node_gradient(&map, p, d, axes[d], idx[d]);
                    node[3 + 3 * d..6 + 3 * d].copy_from_slice(&g);
                }
                nodes.push(node);
            }
        }
    }
    let nid = |i: usize, j: usize, k: usize| i + (nx + 1) * (j + (ny + 1) * k);
    for axis in [0, 1] {
        if (axis == 0 && mirror.x) || (axis == 1 && mirror.y) {
            symmetrize(&mut nodes, [nx, ny, nz], axis);
        }
    }
    let mut elements = Vec::with_capacity(nx * ny * nz);
    let mut lengths = Vec::with_capacity(nx * ny * nz);
    let mut boundary = Vec::new();
    for k in 0..nz {
        for j in 0..ny {
            for i in 0..nx {
                let e = elements.len();
                elements.push([
                    nid(i, j, k),
                    nid(i + 1, j, k),
                    nid(i + 1, j + 1, k),
                    nid(i, j + 1, k),
                    nid(i, j, k + 1),
                    nid(i + 1, j, k + 1),
                    nid(i + 1, j + 1, k + 1),
                    nid(i, j + 1, k + 1),
                ]);
                lengths.push([u[i + 1] - u[i], v[j + 1] - v[j], w[k + 1] - w[k]]);
                let mut add = |face, kind| boundary.push(BoundaryFace { element: e, face, kind });
                if i == 0 {
                    add(Face::XMin, BoundaryKind::Wall);
                }
                if i == nx - 1 {
                    add(Face::XMax, BoundaryKind::Wall);
                }
                if j == 0 {
                    add(Face::YMin, BoundaryKind::Wall);
                }
                if j == ny - 1 {
                    add(Face::YMax, BoundaryKind::Wall);
                }
                if k == 0 {
                    add(Face::ZMin, BoundaryKind::Wall);
                }
                if k == nz - 1 {
                    let kind = if top_is_free_surface { BoundaryKind::FreeSurface } else { BoundaryKind::Wall };
                    add(Face::ZMax, kind);
                }
            }
        }
    }
    FluidMesh { nodes, elements, lengths, counts: [nx, ny, nz], boundary, exact_volume, free_surface_z, kind }
}

/// The planes a map is symmetric about, with its parametric box: `x`, the plane x = 0 with
/// u ↦ len − u; `y`, the plane y = 0 with v ↦ width − v.
#[derive(Debug, Clone, Copy, Default)]
struct Mirror {
    x: bool,
    y: bool,
}

/// The image of a node (position, ∂X/∂u, ∂X/∂v, ∂X/∂w) under the reflection of coordinate
/// `axis` that also reverses parametric direction `axis`: X' = S X, ∂X'/∂p_d = S ∂X/∂p_d for
/// d ≠ axis and −S ∂X/∂p_axis. Sign changes only, so exact.
fn mirror_node(node: &[f64; COORDS_PER_NODE], axis: usize) -> [f64; COORDS_PER_NODE] {
    let mut out = *node;
    for (slot, c) in out.iter_mut().enumerate() {
        let (vector, component) = (slot / 3, slot % 3);
        let flip = (component == axis) != (vector == axis + 1);
        if flip {
            *c = -*c;
        }
    }
    out
}

/// Makes the node grid (`counts` elements) exactly symmetric under [`mirror_node`] about
/// `axis`: a node on the far side of the plane becomes the mirror image of its partner (so it
/// lies inside the region exactly when the partner does), and a node on the plane the mean of
/// itself and its image (its through-plane position and gradient components become 0).
fn symmetrize(nodes: &mut [[f64; COORDS_PER_NODE]], counts: [usize; 3], axis: usize) {
    let [nx, ny, nz] = counts;
    let nid = |i: [usize; 3]| i[0] + (nx + 1) * (i[1] + (ny + 1) * i[2]);
    for k in 0..=nz {
        for j in 0..=ny {
            for i in 0..=nx {
                let idx = [i, j, k];
                let mut partner = idx;
                partner[axis] = counts[axis] - idx[axis];
                if partner[axis] < idx[axis] {
                    continue;
                }
                let (a, b) = (nid(idx), nid(partner));
                if a == b {
                    let image = mirror_node(&nodes[a], axis);
                    for c in 0..COORDS_PER_NODE {
                        nodes[a][c] = 0.5 * (nodes[a][c] + image[c]);
                    }
                } else {
                    nodes[b] = mirror_node(&nodes[a], axis);
                }
            }
        }
    }
}

/// Gradient of `map` along parametric direction `d` at node `idx` of `axis`.
fn node_gradient<M: Fn([f64; 3]) -> [f64; 3]>(map: &M, p: [f64; 3], d: usize, axis: &[f64], idx: usize) -> [f64; 3] {
    let n = axis.len() - 1;
    let h_el = if idx == 0 {
        axis[1] - axis[0]
    } else if idx == n {
        axis[n] - axis[n - 1]
    } else {
        (axis[idx + 1] - axis[idx]).min(axis[idx] - axis[idx - 1])
    };
    let (g, singular) = smooth_gradient(map, p, d, h_el);
    if !singular || (idx != 0 && idx != n) {
        return g;
    }
    // the edge of the map: fit the element edge toward the neighbour
    let (dir, nb) = if idx == 0 { (1.0, 1) } else { (-1.0, n - 1) };
    let mut pn = p;
    pn[d] = axis[nb];
    let (m1, _) = smooth_gradient(map, pn, d, h_el);
    edge_fit(map, p, d, dir * h_el, m1.map(|c| dir * c)).map(|c| dir * c)
}

/// The gradient of `map` along parametric direction `d` at `p` by fourth-order central
/// differences with a small step, and whether it is singular there: then (small-step
/// gradient more than twice the secant one) the secant slope over ±¼ and ±½ of `h_el`
/// instead. The maps are analytic beyond the parametric box as well, so the stencil may
/// leave the domain.
fn smooth_gradient<M: Fn([f64; 3]) -> [f64; 3]>(map: &M, p: [f64; 3], d: usize, h_el: f64) -> ([f64; 3], bool) {
    let diff = |h: f64| -> [f64; 3] {
        let at = |t: f64| {
            let mut q = p;
            q[d] += t;
            map(q)
        };
        let (a2, a1, b1, b2) = (at(2.0 * h), at(h), at(-h), at(-2.0 * h));
        let g = |c: usize| (-a2[c] + 8.0 * a1[c] - 8.0 * b1[c] + b2[c]) / (12.0 * h);
        [g(0), g(1), g(2)]
    };
    let fine = diff(1e-3 * h_el);
    let secant = diff(0.25 * h_el);
    let norm = |g: &[f64; 3]| (g[0] * g[0] + g[1] * g[1] + g[2] * g[2]).sqrt();
    if norm(&fine) > 2.0 * norm(&secant) { (secant, true) } else { (fine, false) }
}

/// The start slope m₀ of the cubic Hermite edge from `p` to `p + h e_d` (signed
/// parametric length `h`) whose end slope is `m1` (both along the edge's direction) that
/// fits `map` along the edge best in least squares, component by component:
/// x(t) = H₀₀x₀ + H₁₀|h|m₀ + H₀₁x₁ + H₁₁|h|m₁, t ∈ [0, 1]; m₀ = ∫H₁₀(x − rest)/(|h|∫H₁₀²),
/// by the midpoint rule on 400 points (the map's √ singularity at t = 0 is integrable).
fn edge_fit<M: Fn([f64; 3]) -> [f64; 3]>(map: &M, p: [f64; 3], d: usize, h: f64, m1: [f64; 3]) -> [f64; 3] {
    const SAMPLES: usize = 400;
    let at = |t: f64| {
        let mut q = p;
        q[d] += t * h;
        map(q)
    };
    let len = h.abs();
    let (x0, x1) = (at(0.0), at(1.0));
    let (mut num, mut den) = ([0.0; 3], 0.0);
    for k in 0..SAMPLES {
        let t = (k as f64 + 0.5) / SAMPLES as f64;
        let (t2, t3) = (t * t, t * t * t);
        let (h00, h10, h01, h11) = (2.0 * t3 - 3.0 * t2 + 1.0, t3 - 2.0 * t2 + t, 3.0 * t2 - 2.0 * t3, t3 - t2);
        let x = at(t);
        for c in 0..3 {
            num[c] += h10 * (x[c] - h00 * x0[c] - h01 * x1[c] - h11 * len * m1[c]);
        }
        den += h10 * h10;
    }
    num.map(|v| v / (len * den))
}

/// A rectangular box of fluid `[x0, x0 + size_x] × …` with `counts` elements.
/// The top face (z max) is the free surface.
pub fn box_mesh(origin: [f64; 3], size: [f64; 3], counts: [usize; 3]) -> Result<FluidMesh> {
    for (d, name) in ["size_x", "size_y", "size_z"].iter().enumerate() {
        check_positive(name, size[d])?;
    }
    for (d, name) in ["n_x", "n_y", "n_z"].iter().enumerate() {
        check_count(name, counts[d])?;
    }
    let u = graded_nodes(counts[0], size[0], 1.0);
    let v = graded_nodes(counts[1], size[1], 1.0);
    let w = graded_nodes(counts[2], size[2], 1.0);
    let map = move |p: [f64; 3]| [origin[0] + p[0], origin[1] + p[1], origin[2] + p[2]];
    Ok(structured(
        &u,
        &v,
        &w,
        map,
        Mirror::default(),
        true,
        size[0] * size[1] * size[2],
        origin[2] + size[2],
        format!("box {}x{}x{} m", size[0], size[1], size[2]),
    ))
}

/// Area of the segment of a circle of radius `r` below the chord at depth `h` from the bottom.
pub fn circle_segment_area(r: f64, h: f64) -> f64 {
    let h = h.clamp(0.0, 2.0 * r);
    let alpha = ((r - h) / r).clamp(-1.0, 1.0).acos();
    r * r * (alpha - alpha.sin() * alpha.cos())
}

/// Liquid volume in a horizontal cylinder (shell length `l`, radius `r`) with two
/// half-ellipsoidal heads of depth `d`, filled to depth `h`.
pub fn tank_liquid_volume(l: f64, r: f64, d: f64, h: f64) -> f64 {
    let h = h.clamp(0.0, 2.0 * r);
    // the two heads form one ellipsoid (d, r, r): a spherical cap scaled by d/r
    l * circle_segment_area(r, h) + (d / r) * std::f64::consts::PI * h * h * (3.0 * r - h) / 3.0
}

/// Depth that gives the liquid volume `target` (bisection on a monotone function).
fn depth_for_volume(vol: impl Fn(f64) -> f64, hmax: f64, target: f64) -> f64 {
    crate::roots::bisect(0.0, hmax, 200, |h| vol(h) < target)
}

/// Coons (transfinite) map of the unit square onto the segment of the ellipse
/// (a cos θ, b sin θ) below the chord z = z_s. The square's bottom and sides map onto
/// the wetted arc (a third of its angular span each), its top onto the chord.
fn segment_map(a: f64, b: f64, zs: f64) -> impl Fn(f64, f64) -> (f64, f64) {
    let tr = (zs / b).clamp(-1.0, 1.0).asin();
    let tl = -std::f64::consts::PI - tr;
    let span = tr - tl;
    let arc = move |t: f64| (a * t.cos(), b * t.sin());
    let p00 = arc(tl + span / 3.0);
    let p10 = arc(tr - span / 3.0);
    let p01 = arc(tl);
    let p11 = arc(tr);
    move |s: f64, t: f64| {
        let bot = arc(tl + span / 3.0 + s * span / 3.0);
        let top = (p01.0 + s * (p11.0 - p01.0), p01.1 + s * (p11.1 - p01.1));
        let left = arc(tl + span / 3.0 - t * span / 3.0);
        let right = arc(tr - span / 3.0 + t * span / 3.0);
        let c = |i: usize| -> f64 {
            let g = |p: (f64, f64)| if i == 0 { p.0 } else { p.1 };
            (1.0 - t) * g(bot) + t * g(top) + (1.0 - s) * g(left) + s * g(right)
                - ((1.0 - s) * (1.0 - t) * g(p00) + s * (1.0 - t) * g(p10) + (1.0 - s) * t * g(p01) + s * t * g(p11))
        };
        (c(0), c(1))
    }
}

/// Specification of the liquid in a horizontal cylindrical tank with half-ellipsoidal
/// heads (the tank car of seed 000 §8.1).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct CylinderTankSpec {
    /// Length of the cylindrical shell between the head tangent lines (m).
    pub length: f64,
    /// Shell radius (m).
    pub radius: f64,
    /// Depth of each half-ellipsoidal head (m); 0 gives flat ends.
    pub head_depth: f64,
    /// Liquid volume as a fraction of the tank volume, in (0, 0.97].
    pub fill: f64,
    /// Elements along the length.
    pub n_length: usize,
    /// Elements across the width.
    pub n_width: usize,
    /// Elements over the height.
    pub n_height: usize,
    /// Ratio of the element length at the front (+x) end to that at the rear (−x) end
    /// (1 = uniform; < 1 refines toward the front).
    pub grading: f64,
}

/// Overall length of the tank car's tank of seed 000 §8.1, heads included ("a length of
/// approximately 12 m"), m: the one home of the tank car's dimensions, read by
/// [`CylinderTankSpec::tank_car`], `rail_mbs::vehicle::TankCarParams::standard` and Python's
/// `railslosh.mesh`.
pub const TANK_CAR_LENGTH: f64 = 12.0;
/// Shell radius of the tank car's tank (seed 000 §8.1: 1.5 m), m.
pub const TANK_CAR_RADIUS: f64 = 1.5;
/// Depth of each of the tank car's half-ellipsoidal heads, m: seed 000 gives a cylindrical tank
/// "with half-ellipsoid ends" but not their depth, so this is our choice (R/3, a typical 2:1-type
/// head for a 3 m diameter DOT-111/117 car); the heads lie within [`TANK_CAR_LENGTH`].
pub const TANK_CAR_HEAD_DEPTH: f64 = 0.5;

impl CylinderTankSpec {
    /// The half-full tank car of seed 000 §8.1 ([`TANK_CAR_LENGTH`] overall: a shell of
    /// `TANK_CAR_LENGTH − 2·TANK_CAR_HEAD_DEPTH` = 11 m between its heads; [`TANK_CAR_RADIUS`],
    /// [`TANK_CAR_HEAD_DEPTH`]) with the given element counts: the vehicle runs' tank
    /// (`rail_mbs::vehicle::TankCarParams::tank_spec`).
    pub fn tank_car(counts: [usize; 3]) -> Self {
        Self {
            length: TANK_CAR_LENGTH - 2.0 * TANK_CAR_HEAD_DEPTH,
            radius: TANK_CAR_RADIUS,
            head_depth: TANK_CAR_HEAD_DEPTH,
            fill: 0.5,
            n_length: counts[0],
            n_width: counts[1],
            n_height: counts[2],
            grading: 1.0,
        }
    }

    /// Validate every field; errors name the field and the allowed range.
    pub fn validate(&self) -> Result<()> {
        check_positive("length", self.length)?;
        check_positive("radius", self.radius)?;
        if !(self.head_depth.is_finite() && self.head_depth >= 0.0 && self.head_depth <= 2.0 * self.radius) {
            return Err(invalid("head_depth", self.head_depth, "a number in [0, 2·radius]"));
        }
        check_fill(self.fill)?;
        check_count("n_length", self.n_length)?;
        check_count("n_width", self.n_width)?;
        check_count("n_height", self.n_height)?;
        check_range("grading", self.grading, 0.05, 20.0)
    }

    /// The walls of this tank: the shell and its heads.
    pub fn shape(&self) -> crate::tank::TankShape {
        crate::tank::TankShape::Cylinder { length: self.length, radius: self.radius, head_depth: self.head_depth }
    }

    /// Total tank volume (m³).
    pub fn tank_volume(&self) -> f64 {
        tank_liquid_volume(self.length, self.radius, self.head_depth, 2.0 * self.radius)
    }

    /// Liquid depth for the requested fill (m).
    pub fn liquid_depth(&self) -> f64 {
        let target = self.fill * self.tank_volume();
        depth_for_volume(
            |h| tank_liquid_volume(self.length, self.radius, self.head_depth, h),
            2.0 * self.radius,
            target,
        )
    }
}

/// The liquid in a partially filled horizontal cylinder with half-ellipsoidal heads.
///
/// Each axial "fibre" through a cross-section point (y, z) runs from the rear head to the
/// front head, so the mesh fills exactly the tank interior below the free surface.
pub fn cylinder_tank(spec: &CylinderTankSpec) -> Result<FluidMesh> {
    spec.validate()?;
    let (l, d) = (spec.length, spec.head_depth);
    let h = spec.liquid_depth();
    let mut mesh = tank_block(spec, h, (None, None), spec.n_length, spec.grading);
    mesh.kind = format!("cylinder tank L={l} R={} head={d} fill={}", spec.radius, spec.fill);
    Ok(mesh)
}

/// The liquid of a tank car between two axial ends, each either a head (`None`) or a
/// bulkhead face at the given x: each axial fibre through a cross-section point runs from
/// one end to the other, `n` elements long with the given grading. The exact volume is that
/// of the tank interior between the ends, below the free surface at depth `h`.
fn tank_block(spec: &CylinderTankSpec, h: f64, ends: (Option<f64>, Option<f64>), n: usize, grading: f64) -> FluidMesh {
    let (l, r, d) = (spec.length, spec.radius, spec.head_depth);
    let (a, b) = ends;
    let zs = h - r;
    let section = segment_map(r, r, zs);
    let width = 2.0 * r;
    let len = b.unwrap_or(0.5 * l + d) - a.unwrap_or(-0.5 * l - d);
    let u = graded_nodes(n, len, grading);
    let v = graded_nodes(spec.n_width, width, 1.0);
    let w = graded_nodes(spec.n_height, h, 1.0);
    let map = move |p: [f64; 3]| {
        let (y, z) = section(p[1] / width, p[2] / h);
        let rho2 = ((y * y + z * z) / (r * r)).min(1.0);
        let xh = 0.5 * l + d * (1.0 - rho2).sqrt();
        let x0 = a.unwrap_or(-xh);
        let x1 = b.unwrap_or(xh);
        [x0 + (p[0] / len) * (x1 - x0), y, z]
    };
    // each head end holds half of the ellipsoid (d, r, r) below the free surface
    let head = |e: Option<f64>| {
        if e.is_none() { 0.5 * (d / r) * std::f64::consts::PI * h * h * (3.0 * r - h) / 3.0 } else { 0.0 }
    };
    let shell = b.unwrap_or(0.5 * l) - a.unwrap_or(-0.5 * l);
    let exact = shell * circle_segment_area(r, h) + head(a) + head(b);
    // the section is symmetric about y = 0; the fibres about x = 0 between two heads, evenly spaced
    let mirror = Mirror { x: ends == (None, None) && grading == 1.0, y: true };
    structured(&u, &v, &w, map, mirror, true, exact, zs, String::new())
}

/// Specification of the liquid in a flat-ended cylinder of elliptical section
/// (the SwRI tank of seed 003: semi-axes 1/√22.9845 and 1/√57.2785 m, length 0.324 m).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EllipticCylinderSpec {
    /// Length along the axis (m).
    pub length: f64,
    /// Horizontal (lateral, y) semi-axis (m).
    pub semi_axis_y: f64,
    /// Vertical (z) semi-axis (m).
    pub semi_axis_z: f64,
    /// Liquid volume fraction in (0, 0.97].
    pub fill: f64,
    /// Elements along the length.
    pub n_length: usize,
    /// Elements across the width.
    pub n_width: usize,
    /// Elements over the height.
    pub n_height: usize,
}

impl EllipticCylinderSpec {
    /// The SwRI tank of seed 003 (22.9845 y² + 57.2785 z² = 1, length 0.324 m), half full.
    pub fn swri(n_length: usize, n_width: usize, n_height: usize) -> Self {
        Self {
            length: 0.324,
            semi_axis_y: 1.0 / 22.9845f64.sqrt(),
            semi_axis_z: 1.0 / 57.2785f64.sqrt(),
            fill: 0.5,
            n_length,
            n_width,
            n_height,
        }
    }

    /// Validate every field.
    pub fn validate(&self) -> Result<()> {
        check_positive("length", self.length)?;
        check_positive("semi_axis_y", self.semi_axis_y)?;
        check_positive("semi_axis_z", self.semi_axis_z)?;
        check_fill(self.fill)?;
        check_count("n_length", self.n_length)?;
        check_count("n_width", self.n_width)?;
        check_count("n_height", self.n_height)
    }
}

/// The liquid in a flat-ended cylinder of elliptical cross-section.
pub fn elliptic_cylinder(spec: &EllipticCylinderSpec) -> Result<FluidMesh> {
    spec.validate()?;
    let (a, b, l) = (spec.semi_axis_y, spec.semi_axis_z, spec.length);
    let area = std::f64::consts::PI * a * b;
    let h = depth_for_volume(|h| (a / b) * circle_segment_area(b, h), 2.0 * b, spec.fill * area);
    let zs = h - b;
    let section = segment_map(a, b, zs);
    let u = graded_nodes(spec.n_length, l, 1.0);
    let v = graded_nodes(spec.n_width, 2.0 * a, 1.0);
    let w = graded_nodes(spec.n_height, h, 1.0);
    let map = move |p: [f64; 3]| {
        let (y, z) = section(p[1] / (2.0 * a), p[2] / h);
        [p[0] - 0.5 * l, y, z]
    };
    Ok(structured(
        &u,
        &v,
        &w,
        map,
        Mirror { x: true, y: true },
        true,
        spec.fill * area * l,
        zs,
        format!("elliptic cylinder a={a:.5} b={b:.5} L={l} fill={}", spec.fill),
    ))
}

/// Concatenate meshes into one (disconnected blocks, e.g. tank compartments).
pub fn merge(blocks: Vec<FluidMesh>, kind: String) -> FluidMesh {
    let mut out = FluidMesh {
        nodes: Vec::new(),
        elements: Vec::new(),
        lengths: Vec::new(),
        counts: [0, 0, 0],
        boundary: Vec::new(),
        exact_volume: 0.0,
        free_surface_z: blocks.first().map_or(0.0, |b| b.free_surface_z),
        kind,
    };
    for b in blocks {
        let (n0, e0) = (out.nodes.len(), out.elements.len());
        out.nodes.extend(b.nodes);
        out.elements.extend(b.elements.iter().map(|e| e.map(|n| n + n0)));
        out.lengths.extend(b.lengths);
        out.boundary.extend(b.boundary.iter().map(|f| BoundaryFace { element: f.element + e0, ..*f }));
        out.counts[0] += b.counts[0];
        out.counts[1] = out.counts[1].max(b.counts[1]);
        out.counts[2] = out.counts[2].max(b.counts[2]);
        out.exact_volume += b.exact_volume;
    }
    out
}

/// The liquid of a tank car divided into compartments by bulkheads (planes across the
/// tank at `bulkheads[i].0` with thickness `bulkheads[i].1`, tank frame). All compartments
/// have the same free-surface height, set by `spec.fill` as a fraction of the tank volume
/// (ignoring the bulkheads); `spec.n_length` elements are shared among the compartments in
/// proportion to their length (at least one each).
pub fn cylinder_tank_compartments(spec: &CylinderTankSpec, bulkheads: &[(f64, f64)]) -> Result<FluidMesh> {
    spec.validate()?;
    let (l, r, d) = (spec.length, spec.radius, spec.head_depth);
    let ltot = l + 2.0 * d;
    let mut cuts = vec![];
    for (i, &(x, t)) in bulkheads.iter().enumerate() {
        check_positive(&format!("bulkheads[{i}].thickness"), t)?;
        if !(x - t / 2.0 > -l / 2.0 && x + t / 2.0 < l / 2.0) {
            return Err(invalid(
                &format!("bulkheads[{i}].x"),
                x,
                &format!("within the shell, in ({}, {})", -l / 2.0, l / 2.0),
            ));
        }
        if let Some(&(xp, tp)) = cuts.last() {
            let (xp, tp): (f64, f64) = (xp, tp);
            if x - t / 2.0 <= xp + tp / 2.0 {
                return Err(invalid(&format!("bulkheads[{i}].x"), x, "increasing and not overlapping"));
            }
        }
        cuts.push((x, t));
    }
    let h = spec.liquid_depth();
    // compartment ends: None = head surface
    let mut ends: Vec<(Option<f64>, Option<f64>)> = Vec::new();
    let mut lo = None;
    for &(x, t) in &cuts {
        ends.push((lo, Some(x - t / 2.0)));
        lo = Some(x + t / 2.0);
    }
    ends.push((lo, None));
    let nominal = |e: Option<f64>, sign: f64| e.unwrap_or(sign * ltot / 2.0);
    let lens: Vec<f64> = ends.iter().map(|(a, b)| nominal(*b, 1.0) - nominal(*a, -1.0)).collect();
    let total: f64 = lens.iter().sum();
    let blocks = ends
        .iter()
        .zip(&lens)
        .map(|(&e, len)| tank_block(spec, h, e, ((spec.n_length as f64 * len / total).round() as usize).max(1), 1.0))
        .collect();
    Ok(merge(blocks, format!("cylinder tank L={l} R={r} head={d} fill={} with {} bulkheads", spec.fill, cuts.len())))
}
