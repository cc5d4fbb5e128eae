//! Fluid–wall and fluid–bulkhead penalty contact (seed 000 §5).
//!
//! Contact is checked at Gauss points of every boundary face of the fluid mesh (walls and
//! free surface alike, so a splashing free surface meets the tank roof). At a point with
//! tank-frame position p and velocity relative to the wall v, every wall with penetration
//! ψ > 0 (see [`crate::tank`]) pushes back with the traction
//!
//! f_n = k_p ψ + c_p |ψ| ψ̇ (≥ 0), ψ̇ = ∇ψ·v, **F_n = −w f_n ∇ψ**,
//!
//! or, on an adhesive wall ([`WallContactLaw::tension_capacity`] p_a > 0), at the wetted
//! points (those of the mesh's wall faces, not of its free surface) also a suction once the
//! liquid pulls away: f_n = k_p ψ down to −p_a at ψ = −p_a/k_p, back to zero at
//! ψ = −2 p_a/k_p, f_n ≥ −p_a throughout ([`normal_force`], "Adhesive walls" below);
//! plus a tangential traction from [`WallFriction`]: none, regularized Coulomb
//! F_t = −w μ f_n v_t/√(|v_t|² + v_ε²) (the seed's f_t = μ f_n), or no-slip as a tangential
//! viscous penalty F_t = −w c_t χ(ψ) v_t. Here w is the reference area the point represents,
//! so k_p is a stiffness per unit area (Pa/m) and the model does not depend on how many
//! points are used. The equal and opposite force acts on the tank at the same point
//! (seed: Q_CB^t); [`WallContact::forces`] returns its resultant and moment.
//!
//! Positions and velocities are mapped into the tank frame with the tank kinematics
//! (R, A, Ṙ, ω): p = Aᵀ(r − R), v = Aᵀ(ṙ − Ṙ − ω × (r − R)). In a tank-frame formulation
//! pass [`TankKinematics::identity`].
//!
//! # Adhesive walls
//!
//! A liquid below its free surface cannot leave an impermeable wall without cavitating or
//! letting air in; potential-flow theory keeps it on the wall (u·n = 0). The penalty liquid,
//! with its artificial sound speed √(k_IC/ρ) (36 m/s in seed 003's tank), carries transient
//! tension, and on a unilateral wall that tension peels the wetted faces off the wall for a
//! millisecond or two; they then slap back. Measured on seed 003's tank under the 0.3 g pulse
//! (docs/validation.md, "Wall peeling"): points on the wall face at 45–85 % of the depth
//! leave the wall and return within 0.25 ms with up to 5.5 N each, 30–40 N on the whole load
//! of the 2×4×2 mesh; the spikes carry the raw peak and add zero crossings. An adhesive wall
//! holds the wetted points with a suction of at most p_a (the cohesive law above: elastic
//! down to −p_a, softening to zero over the next p_a/k_p), so a wetted point leaves the wall
//! only when the liquid pulls with more than p_a, as where air reaches it from the free
//! surface in violent sloshing. The law is conservative (its potential is in
//! [`WallContact::stored_energy`]); the damping c_p |ψ| ψ̇ acts only where ψ > 0.
//!
//! # Culling (which points are checked)
//!
//! [`WallContact::forces`] skips, face by face, the points that provably touch no wall;
//! the result is bit-identical to checking every point (`forces_full`). The points k of a
//! group ("cell") of one boundary face are all interpolated from the same element's nodal
//! vectors e_a with stored shape values S_ka. Since the position functions are a partition
//! of unity, Σ_pos S_ka = 1 + η_k with |η_k| ≤ η (rounding of the stored values, ~1e-16,
//! precomputed), and the tank-frame position is exactly
//!
//! p_k = Aᵀ(r_k − R) = w_o + Σ_a S_ka u_a + η_k (w_o + AᵀR),
//!
//! with w_a = Aᵀ(e_a − R), w_o their mean over the face's position nodes, u_a = w_a − w_o
//! (positions; centring keeps the intervals below element-sized) and u_a = Aᵀe_a
//! (gradients). With lo_a ≤ S_ka ≤ hi_a over the cell (precomputed), interval arithmetic
//! puts every p_k in the box w_o + Σ_a [min(lo_a u_ai, hi_a u_ai), max(lo_a u_ai, hi_a u_ai)]
//! ± η (|w_o| + ‖A‖_F |R|). If [`TankGeometry::box_clearance`] of that box (a lower bound on
//! its distance to every point where a wall would be reported) exceeds a rounding margin of
//! 10⁻⁹ × (tank size + |R| + the box's largest coordinate) — the rounding of these sums
//! and of the point positions is below 10⁻¹³ of the same magnitudes — no point of the
//! cell can hit a wall and it is skipped. Each face is tested as one cell and, if that
//! fails, as 2×2 sub-cells. Faces whose points disagree on their bulkhead sides are
//! always checked; non-finite data never culls.
//!
//! Trying the bound costs about as much as checking a few points, and faces on the walls
//! are never culled, so it is tried only where it may pay off: on faces away from the
//! walls in the reference state (the free surface, ...) whose node centroid is currently
//! farther from the walls than a quarter of the face size. These heuristics only decide
//! which faces are tried; they never change a result. Measured (`cargo bench -p ancf-core
//! --bench contact`), the cull saves about as much as it costs on the tank-car meshes: the
//! gain over the previous pass comes mostly from the leaner per-point work (velocity only
//! at points that hit a wall, no Jacobian or Hessian work without `jacobians`, one gather
//! of the nodal vectors per face, no allocation). The cull data is built by
//! [`WallContact::new`]; treat `points` as read-only (if their number changes, `forces`
//! falls back to the full check).

use nalgebra::Vector3;

use crate::body::{FluidBody, gather_compact};
use crate::constitutive::{M3, smoothstep};
use crate::element::scaled;
use crate::error::{Result, check_non_negative, check_positive, invalid};
use crate::mesh::{BoundaryKind, Face};
use crate::quadrature::{gauss_legendre, gauss_lobatto};
use crate::shape::{N_SHAPE, normalized_shape};
use crate::tank::{TankGeometry, WallHit};

/// Tangential behaviour at the walls.
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum WallFriction {
    /// No tangential force (free slip).
    Frictionless,
    /// Regularized Coulomb friction f_t = μ f_n (seed 000 §5.2).
    Coulomb {
        /// Friction coefficient μ.
        coefficient: f64,
        /// Regularization slip velocity v_ε (m/s).
        slip_velocity: f64,
    },
    /// No-slip as a tangential viscous penalty F_t = −c_t χ(ψ) v_t per unit area.
    NoSlip {
        /// Drag coefficient c_t (Pa·s/m).
        drag: f64,
        /// Penetration over which the drag switches on smoothly (m).
        activation_depth: f64,
    },
}

/// Where the contact points sit on each boundary face.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactPointRule {
    /// Gauss–Legendre points: interior to the face, so nodes, edges and corners are not
    /// checked and can pass through a wall between the points.
    Gauss,
    /// Gauss–Lobatto points: the face's nodes, edges and corners are contact points too
    /// (a corner shared by faces is a point of each, with its own area weight).
    Lobatto,
}

/// Penalty contact law.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WallContactLaw {
    /// k_p, normal stiffness per unit area (Pa/m).
    pub stiffness: f64,
    /// c_p of f_n = k_p ψ + c_p |ψ| ψ̇ (Pa·s/m²).
    pub damping: f64,
    /// Tangential law.
    pub friction: WallFriction,
    /// Points per face edge (points per face = this squared).
    pub points_per_edge: usize,
    /// Where the points sit on a face (default [`ContactPointRule::Gauss`]).
    pub point_rule: ContactPointRule,
    /// p_a, the largest suction (Pa) an adhesive wall holds on the wetted points (module
    /// docs, "Adhesive walls"); 0 (the default): a unilateral wall.
    pub tension_capacity: f64,
}

/// The normal wall traction f_n (Pa; > 0 pushes the liquid back, < 0 holds it on an
/// adhesive wall) at wall gap ψ (m, > 0 beyond the wall) and gap rate ψ̇ (m/s), for
/// stiffness k, damping c and tension capacity p_a (0 on a unilateral wall and at points
/// that are not wetted), with its partial derivatives: `(f_n, ∂f_n/∂ψ, ∂f_n/∂ψ̇)`. `None`:
/// no traction.
///
/// - ψ > 0: f_n = ψ (k + c ψ̇), at least −p_a (the clamp carries no derivative);
/// - −p_a/k ≤ ψ ≤ 0: f_n = k ψ (suction);
/// - −2 p_a/k < ψ < −p_a/k: f_n = −k (ψ + 2 p_a/k) (softening to zero).
pub fn normal_force(k: f64, c: f64, tension_capacity: f64, psi: f64, psid: f64) -> Option<(f64, f64, f64)> {
    if psi > 0.0 {
        let f = psi * (k + c * psid);
        return if f > -tension_capacity {
            Some((f, k + c * psid, c * psi))
        } else if tension_capacity > 0.0 {
            Some((-tension_capacity, 0.0, 0.0))
        } else {
            None
        };
    }
    let s = tension_capacity / k;
    if psi >= -s {
        (tension_capacity > 0.0).then_some((k * psi, k, 0.0))
    } else if psi > -2.0 * s {
        Some((-k * (psi + 2.0 * s), -k, 0.0))
    } else {
        None
    }
}

/// The potential of the elastic part of [`normal_force`] per unit area (J/m²), zero for a
/// point out of reach (ψ ≤ −2 p_a/k): ½ k ψ² − k s² for ψ ≥ −s (s = p_a/k; −k s² is the
/// binding energy of a wetted point at the wall), −½ k (ψ + 2s)² beyond.
pub fn normal_potential(k: f64, tension_capacity: f64, psi: f64) -> f64 {
    let s = tension_capacity / k;
    if psi >= -s {
        0.5 * k * psi * psi - k * s * s
    } else if psi > -2.0 * s {
        -0.5 * k * (psi + 2.0 * s) * (psi + 2.0 * s)
    } else {
        0.0
    }
}

/// Default damping ratio ζ_w of the liquid column on the penalty wall spring
/// ([`WallContactLaw::default_for`]). The column-on-spring mode, (1/2π)√(k_p/(ρ L)) = 20–30 Hz
/// in the tanks here, is an artefact of the penalty wall (a liquid does not rebound from a
/// wall), and at ζ_w = 0.1 it rings in the loads after an impact; ζ_w = 1 (critical) removes
/// most of that ringing at a higher cost per simulated second (docs/validation.md, "Wall
/// damping"). Runs choose it with [`WallContactLaw::with_damping_ratio`] (`wall_damping_ratio`
/// of scenes and the Python API).
pub const WALL_DAMPING_RATIO: f64 = 0.1;

impl WallContactLaw {
    /// Defaults derived from the fluid and the liquid depth H (see `docs/architecture.md`):
    /// - k_p = 1000 ρ g: the hydrostatic pressure at the bottom, ρ g H, is carried with a
    ///   penetration δ_e = 10⁻³ H;
    /// - c_p such that the liquid column bouncing on the wall (mass ρH per unit area on the
    ///   spring k_p) has the damping ratio [`WALL_DAMPING_RATIO`] at the equilibrium
    ///   penetration: c_p δ_e = 2 ζ_w √(k_p ρ H);
    /// - frictionless walls; 3×3 points per face.
    pub fn default_for(density: f64, gravity: f64, depth: f64) -> Self {
        let k = 1000.0 * density * gravity;
        let mut law = Self {
            stiffness: k,
            damping: 0.0,
            friction: WallFriction::Frictionless,
            points_per_edge: 3,
            point_rule: ContactPointRule::Gauss,
            tension_capacity: 0.0,
        };
        law.damping = law.damping_for_ratio(WALL_DAMPING_RATIO, density, gravity, depth);
        law
    }

    /// c_p that gives the liquid column of depth `depth` on this law's wall spring the damping
    /// ratio `zeta` at the equilibrium penetration δ_e = ρ g H / k_p: c_p = 2 ζ √(k_p ρ H)/δ_e.
    pub fn damping_for_ratio(&self, zeta: f64, density: f64, gravity: f64, depth: f64) -> f64 {
        let delta_e = density * gravity * depth / self.stiffness;
        2.0 * zeta * (self.stiffness * density * depth).sqrt() / delta_e
    }

    /// This law with the wall damping ratio `zeta` (finite, in [0, 10]) for a liquid of
    /// `density` and `depth` under `gravity` ([`Self::damping_for_ratio`]).
    pub fn with_damping_ratio(mut self, zeta: f64, density: f64, gravity: f64, depth: f64) -> Result<Self> {
        if !(zeta.is_finite() && (0.0..=10.0).contains(&zeta)) {
            return Err(invalid("wall_damping_ratio", zeta, "a number in [0, 10]"));
        }
        self.damping = self.damping_for_ratio(zeta, density, gravity, depth);
        Ok(self)
    }

    /// This law with an adhesive wall holding the wetted points with up to `ratio` times the
    /// hydrostatic pressure at the bottom of a liquid of `density` and `depth` under `gravity`:
    /// p_a = ratio ρ g H (finite, `ratio` in [0, 50]; 0: a unilateral wall).
    pub fn with_adhesion(mut self, ratio: f64, density: f64, gravity: f64, depth: f64) -> Result<Self> {
        if !(ratio.is_finite() && (0.0..=50.0).contains(&ratio)) {
            return Err(invalid("wall_adhesion", ratio, "a number in [0, 50]"));
        }
        self.tension_capacity = ratio * density * gravity * depth;
        Ok(self)
    }

    /// How far inside the tank (m) an adhesive wall still acts on a wetted point,
    /// 2 p_a/k_p ([`normal_force`]); 0 for a unilateral wall.
    pub fn reach(&self) -> f64 {
        2.0 * self.tension_capacity / self.stiffness
    }

    /// Validate; errors name the field.
    pub fn validate(&self) -> Result<()> {
        check_positive("contact.stiffness", self.stiffness)?;
        check_non_negative("contact.damping", self.damping)?;
        check_non_negative("contact.tension_capacity", self.tension_capacity)?;
        if !(1..=6).contains(&self.points_per_edge) {
            return Err(invalid("contact.points_per_edge", self.points_per_edge, "an integer in [1, 6]"));
        }
        if self.point_rule == ContactPointRule::Lobatto && self.points_per_edge < 2 {
            return Err(invalid(
                "contact.points_per_edge",
                self.points_per_edge,
                "an integer in [2, 6] with Gauss-Lobatto points (they include both face edges)",
            ));
        }
        match self.friction {
            WallFriction::Frictionless => Ok(()),
            WallFriction::Coulomb { coefficient, slip_velocity } => {
                check_non_negative("contact.friction.coefficient", coefficient)?;
                check_positive("contact.friction.slip_velocity", slip_velocity)
            }
            WallFriction::NoSlip { drag, activation_depth } => {
                check_non_negative("contact.friction.drag", drag)?;
                check_positive("contact.friction.activation_depth", activation_depth)
            }
        }
    }
}

/// Rigid motion of the tank: position R of its origin, rotation A (tank → global),
/// velocity Ṙ and angular velocity ω (global components).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct TankKinematics {
    /// R (m).
    pub position: [f64; 3],
    /// A, columns are the tank axes in global components.
    pub rotation: M3,
    /// Ṙ (m/s).
    pub velocity: [f64; 3],
    /// ω (rad/s), global components.
    pub angular_velocity: [f64; 3],
}

impl TankKinematics {
    /// The tank at rest at the global origin (tank frame = global frame).
    pub fn identity() -> Self {
        Self { position: [0.0; 3], rotation: M3::identity(), velocity: [0.0; 3], angular_velocity: [0.0; 3] }
    }
}

/// A contact point on the fluid boundary.
#[derive(Debug, Clone)]
pub struct ContactPoint {
    /// Element index.
    pub element: usize,
    /// Physical shape-function values N_a at the point (32).
    pub shape: [f64; N_SHAPE],
    /// Reference area represented by the point (m²).
    pub weight: f64,
    /// Side of each bulkhead on which the point's liquid lies.
    pub sides: Vec<i8>,
    /// On a wall face of the mesh (wetted; an adhesive wall holds it), not on the free
    /// surface.
    pub wetted: bool,
}

/// Resultant contact load on the tank and diagnostics.
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub struct ContactLoad {
    /// Force of the fluid on the tank through contact (N, global).
    pub force: [f64; 3],
    /// Its moment about the tank origin R (N·m, global).
    pub moment: [f64; 3],
    /// Number of points in contact.
    pub active: usize,
    /// Largest penetration (m).
    pub max_penetration: f64,
}

/// Jacobian of the contact force at one active point (global frame).
#[derive(Debug, Clone, Copy)]
pub struct PointJacobian {
    /// Index into [`WallContact::points`].
    pub point: usize,
    /// ∂F/∂r.
    pub d_position: M3,
    /// ∂F/∂ṙ.
    pub d_velocity: M3,
    /// The contact force F on the fluid at this point (N, global).
    pub force: Vector3<f64>,
    /// The point's position relative to the tank origin, r − R (m, global).
    pub arm: Vector3<f64>,
}

/// Contact between one fluid body and one tank.
#[derive(Debug, Clone)]
pub struct WallContact {
    /// Tank walls and bulkheads.
    pub geometry: TankGeometry,
    /// Contact law.
    pub law: WallContactLaw,
    /// Contact points (grouped by boundary face; read-only after construction, see the
    /// module docs on culling).
    pub points: Vec<ContactPoint>,
    /// Cull data of each boundary face, in the order of `points`.
    faces: Vec<FaceCull>,
    /// Bulkhead sides of each mesh node (from its reference position).
    node_sides: Vec<Vec<i8>>,
}

/// A place in the liquid checked for containment ([`WallContact::containment`]).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum FluidSite {
    /// A mesh node (its position coordinates).
    Node(usize),
    /// A contact point on the boundary ([`WallContact::points`]) of `element`.
    ContactPoint {
        /// Index into [`WallContact::points`].
        point: usize,
        /// Its element.
        element: usize,
    },
    /// The liquid's centre of mass (checked against the shell only).
    CentreOfMass,
}

impl std::fmt::Display for FluidSite {
    fn fmt(&self, f: &mut std::fmt::Formatter<'_>) -> std::fmt::Result {
        match self {
            Self::Node(n) => write!(f, "fluid node {n}"),
            Self::ContactPoint { point, element } => write!(f, "contact point {point} (element {element})"),
            Self::CentreOfMass => f.write_str("liquid centre of mass"),
        }
    }
}

/// The deepest place of the liquid beyond its walls ([`WallContact::containment`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Breach {
    /// Where.
    pub site: FluidSite,
    /// Its tank-frame position (m).
    pub position: [f64; 3],
    /// How far beyond the wall (ψ > 0, m).
    pub depth: f64,
}

/// Culling mode of [`WallContact::forces_counted`] (tests and benchmarks).
#[doc(hidden)]
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum Cull {
    /// Check every point.
    Off,
    /// As [`WallContact::forces`]: try the bound on the faces worth it.
    On,
    /// Try the bound on every face (no performance heuristics), to test the bound.
    Always,
}

/// Bit a set for the position functions (a = 0, 4, ..., 28).
const POSITION_FUNCTIONS: u32 = 0x1111_1111;

/// Faces are tried for culling only if their node centroid's clearance exceeds this
/// fraction of their size (see `skip_mask`).
const CULL_GATE: f64 = 0.25;

/// A group of points of one face with its bound data (module docs, "Culling").
#[derive(Debug, Clone)]
struct CullCell {
    /// Bit i set: point `start + i` of the face belongs to the cell.
    mask: u64,
    /// lo_a = min over the cell's points of S_ka.
    lo: [f64; N_SHAPE],
    /// hi_a = max over the cell's points of S_ka.
    hi: [f64; N_SHAPE],
}

/// The points of one boundary face: `points[start..start + len]`, all of `element`.
#[derive(Debug, Clone)]
struct FaceCull {
    start: usize,
    len: usize,
    element: usize,
    /// Shape functions not identically zero on the face (bit a).
    used: u32,
    /// Bound on |Σ_pos S_ka − 1| over the face's points, rounding included.
    eta: f64,
    /// False: never culled (points on different bulkhead sides).
    cullable: bool,
    /// False: not worth trying (a face on the walls in the reference state, see
    /// `WallContact::new`); [`Cull::Always`] tries it anyway.
    candidate: bool,
    /// The whole face first, then its 2×2 sub-cells.
    cells: Vec<CullCell>,
}

/// Per-point accumulator of [`WallContact::point_force`]'s sums, hit by hit.
struct PointAcc {
    /// Walls hit so far.
    hits: usize,
    f: Vector3<f64>,
    jp: M3,
    jv: M3,
}

impl WallContact {
    /// Sample contact points on every boundary face of `body`'s mesh. The bulkhead side of
    /// each point is taken from its reference position (the tank frame at t = 0).
    pub fn new(body: &FluidBody, geometry: TankGeometry, law: WallContactLaw) -> Result<Self> {
        law.validate()?;
        let (gx, gw) = match law.point_rule {
            ContactPointRule::Gauss => gauss_legendre(law.points_per_edge)?,
            ContactPointRule::Lobatto => gauss_lobatto(law.points_per_edge)?,
        };
        let mut points = Vec::new();
        let mut faces = Vec::new();
        let ppe = law.points_per_edge;
        for bf in &body.mesh.boundary {
            let el = bf.element;
            let wetted = bf.kind == BoundaryKind::Wall;
            let r = &body.elements[el];
            let ehat = scaled(&gather_compact(&body.mesh.nodes, &body.mesh.elements[el]), &r.scale);
            let (fixed, val, (d1, d2)) = match bf.face {
                Face::XMin => (0, -1.0, (1, 2)),
                Face::XMax => (0, 1.0, (1, 2)),
                Face::YMin => (1, -1.0, (0, 2)),
                Face::YMax => (1, 1.0, (0, 2)),
                Face::ZMin => (2, -1.0, (0, 1)),
                Face::ZMax => (2, 1.0, (0, 1)),
            };
            for (s, ws) in gx.iter().zip(&gw) {
                for (t, wt) in gx.iter().zip(&gw) {
                    let mut xi = [0.0; 3];
                    xi[fixed] = val;
                    xi[d1] = *s;
                    xi[d2] = *t;
                    let (n, dn) = normalized_shape(xi);
                    let mut x = Vector3::zeros();
                    let mut t1 = Vector3::zeros();
                    let mut t2 = Vector3::zeros();
                    let mut shape = [0.0; N_SHAPE];
                    for a in 0..N_SHAPE {
                        let ea = Vector3::from(ehat[a]);
                        x += ea * n[a];
                        t1 += ea * dn[a][d1];
                        t2 += ea * dn[a][d2];
                        shape[a] = n[a] * r.scale[a];
                    }
                    let weight = ws * wt * t1.cross(&t2).norm();
                    let sides = geometry.sides([x[0], x[1], x[2]]);
                    points.push(ContactPoint { element: el, shape, weight, sides, wetted });
                }
            }
            let start = points.len() - ppe * ppe;
            faces.push(face_cull(&points[start..], start, el, ppe));
        }
        // Try the cull only on faces whose node centroid is, in the reference state, away
        // from the walls (free surface, ...): wall faces are hardly ever culled, and the
        // test would cost more than it saves. A heuristic on performance only: any face
        // may be checked in full.
        let e0 = body.reference_coordinates();
        for f in faces.iter_mut().filter(|f| f.cullable) {
            let nodes = &body.mesh.elements[f.element];
            let pos: Vec<Vector3<f64>> = (0..N_SHAPE)
                .filter(|a| a % 4 == 0 && f.used >> a & 1 == 1)
                .map(|a| {
                    let g = 3 * (4 * nodes[a / 4]);
                    Vector3::new(e0[g], e0[g + 1], e0[g + 2])
                })
                .collect();
            let wo = pos.iter().sum::<Vector3<f64>>() / pos.len() as f64;
            let size = pos.iter().fold(0.0f64, |m, x| m.max((x - wo).norm()));
            f.candidate = geometry.clearance([wo[0], wo[1], wo[2]], &points[f.start].sides) > CULL_GATE * size;
        }
        let node_sides = body.mesh.nodes.iter().map(|n| geometry.sides([n[0], n[1], n[2]])).collect();
        Ok(Self { geometry, law, points, faces, node_sides })
    }

    /// The deepest place of the liquid beyond its walls: every mesh node, every contact
    /// point and the centre of mass (against the shell; nodes and points also against the
    /// bulkheads of their compartment), as the largest wall gap ψ > 0 in the tank frame.
    /// `None`: everything is inside. Non-finite positions are reported with depth +∞.
    pub fn containment(&self, body: &FluidBody, kin: &TankKinematics, e: &[f64]) -> Option<Breach> {
        let at = kin.rotation.transpose();
        let rt = Vector3::from(kin.position);
        let mut worst: Option<Breach> = None;
        let mut consider = |site: FluidSite, r: Vector3<f64>, sides: &[i8]| {
            let p = at * (r - rt);
            let p = [p[0], p[1], p[2]];
            let mut depth = if p.iter().all(|x| x.is_finite()) { 0.0 } else { f64::INFINITY };
            self.geometry.for_each_hit_with(p, sides, false, 0.0, |h| depth = f64::max(depth, h.psi));
            if depth > 0.0 && worst.is_none_or(|w| depth > w.depth) {
                worst = Some(Breach { site, position: p, depth });
            }
        };
        for (n, sides) in self.node_sides.iter().enumerate() {
            let g = 12 * n;
            consider(FluidSite::Node(n), Vector3::new(e[g], e[g + 1], e[g + 2]), sides);
        }
        for (k, pt) in self.points.iter().enumerate() {
            let r = self.point_position(body, k, e);
            consider(FluidSite::ContactPoint { point: k, element: pt.element }, r, &pt.sides);
        }
        consider(FluidSite::CentreOfMass, Vector3::from(body.center_of_mass(e)), &[]);
        worst
    }

    /// Energy stored in the contact springs, Σ w ½ k_p ψ² over every contact point and
    /// every wall it penetrates (J): the potential of the elastic part of the contact force
    /// (on an adhesive wall, [`normal_potential`] at the wetted points within reach).
    pub fn stored_energy(&self, body: &FluidBody, kin: &TankKinematics, e: &[f64]) -> f64 {
        let at = kin.rotation.transpose();
        let rt = Vector3::from(kin.position);
        let k_p = self.law.stiffness;
        let mut u = 0.0;
        for (k, pt) in self.points.iter().enumerate() {
            let p = at * (self.point_position(body, k, e) - rt);
            let (capacity, reach) = self.adhesion(pt);
            self.geometry.for_each_hit_with([p[0], p[1], p[2]], &pt.sides, false, reach, |h| {
                u += if capacity > 0.0 {
                    pt.weight * normal_potential(k_p, capacity, h.psi)
                } else {
                    0.5 * pt.weight * k_p * h.psi * h.psi
                };
            });
        }
        u
    }

    /// The tension capacity and reach of the wall at point `pt`: the law's for a wetted
    /// point, none for a free-surface point.
    fn adhesion(&self, pt: &ContactPoint) -> (f64, f64) {
        if pt.wetted { (self.law.tension_capacity, self.law.reach()) } else { (0.0, 0.0) }
    }

    /// Position of contact point `k` (global).
    fn point_position(&self, body: &FluidBody, k: usize, e: &[f64]) -> Vector3<f64> {
        let pt = &self.points[k];
        let nodes = &body.mesh.elements[pt.element];
        (0..N_SHAPE).fold(Vector3::zeros(), |r, a| {
            let g = 3 * (4 * nodes[a / 4] + a % 4);
            r + pt.shape[a] * Vector3::new(e[g], e[g + 1], e[g + 2])
        })
    }

    /// Position and velocity of a contact point (global).
    fn point_state(&self, body: &FluidBody, k: usize, e: &[f64], edot: &[f64]) -> (Vector3<f64>, Vector3<f64>) {
        let pt = &self.points[k];
        let nodes = &body.mesh.elements[pt.element];
        let mut r = Vector3::zeros();
        let mut v = Vector3::zeros();
        for a in 0..N_SHAPE {
            let g = 3 * (4 * nodes[a / 4] + a % 4);
            let na = pt.shape[a];
            r += na * Vector3::new(e[g], e[g + 1], e[g + 2]);
            v += na * Vector3::new(edot[g], edot[g + 1], edot[g + 2]);
        }
        (r, v)
    }

    /// Add the contact generalized forces on the fluid to `out` and return the load on the
    /// tank. With `jacobians`, also collect the point Jacobians of every active point.
    ///
    /// Points that provably touch no wall are skipped (module docs, "Culling"); the
    /// results are bit-identical to checking every point. No allocation besides pushes to
    /// `jacobians`.
    pub fn forces(
        &self,
        body: &FluidBody,
        kin: &TankKinematics,
        e: &[f64],
        edot: &[f64],
        out: &mut [f64],
        jacobians: Option<&mut Vec<PointJacobian>>,
    ) -> ContactLoad {
        self.forces_counted(body, kin, e, edot, out, jacobians, Cull::On).0
    }

    /// [`Self::forces`], also returning how many points were checked (positions
    /// evaluated), with the cull as `cull` says (same results in every mode).
    #[doc(hidden)]
    #[allow(clippy::too_many_arguments)]
    pub fn forces_counted(
        &self,
        body: &FluidBody,
        kin: &TankKinematics,
        e: &[f64],
        edot: &[f64],
        out: &mut [f64],
        mut jacobians: Option<&mut Vec<PointJacobian>>,
        cull: Cull,
    ) -> (ContactLoad, usize) {
        if self.faces.last().map_or(0, |f| f.start + f.len) != self.points.len() {
            // `points` was edited after construction: the cull data no longer applies
            return (self.forces_full(body, kin, e, edot, out, jacobians), self.points.len());
        }
        let mut load = ContactLoad::default();
        let a_mat = kin.rotation;
        let at = a_mat.transpose();
        let rt = Vector3::from(kin.position);
        let vt0 = Vector3::from(kin.velocity);
        let w = Vector3::from(kin.angular_velocity);
        let wt = w.cross_matrix();
        let want_jac = jacobians.is_some();
        if let Some(j) = jacobians.as_mut() {
            j.clear();
        }
        let base_margin = self.geometry.size() + rt.norm();
        let eta_scale = a_mat.norm() * rt.norm();
        let mut checked = 0;
        for face in &self.faces {
            let nodes = &body.mesh.elements[face.element];
            let mut g = [0usize; N_SHAPE];
            let mut ea = [Vector3::zeros(); N_SHAPE];
            for a in 0..N_SHAPE {
                g[a] = 3 * (4 * nodes[a / 4] + a % 4);
                ea[a] = Vector3::new(e[g[a]], e[g[a] + 1], e[g[a] + 2]);
            }
            let tried = face.cullable
                && match cull {
                    Cull::Off => false,
                    Cull::On => face.candidate,
                    Cull::Always => true,
                };
            let skip = if tried {
                self.skip_mask(face, &ea, &at, &rt, base_margin, eta_scale, cull == Cull::Always)
            } else {
                0
            };
            for i in 0..face.len {
                if skip >> i & 1 == 1 {
                    continue;
                }
                let k = face.start + i;
                let pt = &self.points[k];
                checked += 1;
                // the same operations, in the same order, as `forces_full`
                let mut r = Vector3::zeros();
                for a in 0..N_SHAPE {
                    r += pt.shape[a] * ea[a];
                }
                let d = r - rt;
                let p = at * d;
                let mut acc = PointAcc { hits: 0, f: Vector3::zeros(), jp: M3::zeros(), jv: M3::zeros() };
                let mut v: Option<Vector3<f64>> = None;
                let (capacity, reach) = self.adhesion(pt);
                self.geometry.for_each_hit_with([p[0], p[1], p[2]], &pt.sides, want_jac, reach, |h| {
                    // the velocity only where some wall is hit
                    let v = *v.get_or_insert_with(|| {
                        let mut rd = Vector3::zeros();
                        for a in 0..N_SHAPE {
                            rd += pt.shape[a] * Vector3::new(edot[g[a]], edot[g[a] + 1], edot[g[a] + 2]);
                        }
                        at * (rd - vt0 - w.cross(&d))
                    });
                    self.add_hit(&mut acc, &h, &v, pt.weight, capacity, want_jac);
                    load.max_penetration = load.max_penetration.max(h.psi);
                });
                if acc.hits == 0 {
                    continue;
                }
                let f = a_mat * acc.f;
                load.active += 1;
                for a in 0..N_SHAPE {
                    let o = &mut out[g[a]..g[a] + 3];
                    for i in 0..3 {
                        o[i] += pt.shape[a] * f[i];
                    }
                }
                let m = d.cross(&(-f));
                for i in 0..3 {
                    load.force[i] -= f[i];
                    load.moment[i] += m[i];
                }
                if let Some(j) = jacobians.as_mut() {
                    let dv = a_mat * acc.jv * at;
                    let dp = a_mat * acc.jp * at - dv * wt;
                    j.push(PointJacobian { point: k, d_position: dp, d_velocity: dv, force: f, arm: d });
                }
            }
        }
        (load, checked)
    }

    /// Bit i set: point `face.start + i` provably hits no wall (module docs, "Culling").
    fn skip_mask(
        &self,
        face: &FaceCull,
        ea: &[Vector3<f64>; N_SHAPE],
        at: &M3,
        rt: &Vector3<f64>,
        base_margin: f64,
        eta_scale: f64,
        ungated: bool,
    ) -> u64 {
        let used = |mut bits: u32| {
            std::iter::from_fn(move || {
                (bits != 0).then(|| {
                    let a = bits.trailing_zeros() as usize;
                    bits &= bits - 1;
                    a
                })
            })
        };
        // u_a = Aᵀ(e_a − R) − w_o (positions; w_o: their mean over the face), Aᵀe_a (gradients)
        let mut u = [Vector3::zeros(); N_SHAPE];
        let mut wo = Vector3::zeros();
        let mut n = 0.0;
        let pos = face.used & POSITION_FUNCTIONS;
        for a in used(pos) {
            u[a] = at * (ea[a] - rt);
            wo += u[a];
            n += 1.0;
        }
        wo /= n;
        let mut spread = 0.0f64;
        for a in used(pos) {
            u[a] -= wo;
            spread = spread.max(u[a].norm_squared());
        }
        let sides = &self.points[face.start].sides;
        // (an adhesive wall acts on wetted points within its reach inside the tank; the
        // clearance is a distance, ψ the first-order distance beyond the wall: twice the reach)
        let reach = 2.0 * self.adhesion(&self.points[face.start]).1;
        // Cheap gate (a heuristic: it only decides whether to try the bound): a face whose
        // node centroid is closer to a wall than a fraction of the face's size is hardly
        // ever culled (faces on the walls), and trying costs more than it saves.
        if !ungated && !(self.geometry.clearance([wo[0], wo[1], wo[2]], sides) > CULL_GATE * spread.sqrt()) {
            return 0;
        }
        for a in used(face.used & !POSITION_FUNCTIONS) {
            u[a] = at * ea[a];
        }
        let slack = face.eta * (wo.norm() + eta_scale);
        let clear = |cell: &CullCell| {
            let mut lo = [wo[0] - slack, wo[1] - slack, wo[2] - slack];
            let mut hi = [wo[0] + slack, wo[1] + slack, wo[2] + slack];
            for a in used(face.used) {
                for i in 0..3 {
                    let (x, y) = (cell.lo[a] * u[a][i], cell.hi[a] * u[a][i]);
                    lo[i] += x.min(y);
                    hi[i] += x.max(y);
                }
            }
            let extent = lo.iter().chain(&hi).fold(0.0f64, |m, v| m.max(v.abs()));
            let margin = 1e-9 * (base_margin + extent);
            self.geometry.box_clearance(lo, hi, sides) > margin + reach
        };
        if clear(&face.cells[0]) {
            return face.cells[0].mask;
        }
        face.cells[1..].iter().filter(|cell| clear(cell)).fold(0, |m, cell| m | cell.mask)
    }

    /// Adds one wall hit to a point's force (and Jacobians if `jac`): the operations of
    /// [`Self::point_force`] for that hit, in the same order.
    fn add_hit(&self, acc: &mut PointAcc, h: &WallHit, v: &Vector3<f64>, w: f64, capacity: f64, jac: bool) {
        let (k, c) = (self.law.stiffness, self.law.damping);
        acc.hits += 1;
        let g = Vector3::from(h.grad);
        let hm = h.hess;
        let psi = h.psi;
        let psid = g.dot(v);
        // (without `jac`, hm is zero and only the force is used)
        let hv = if jac { hm * v } else { Vector3::zeros() };
        let (fnorm, dfn_dp, dfn_dv) = match normal_force(k, c, capacity, psi, psid) {
            Some((f, d_psi, d_psid)) => (f, d_psi * g + d_psid * hv, d_psid * g),
            None => (0.0, Vector3::zeros(), Vector3::zeros()),
        };
        acc.f -= w * fnorm * g;
        if jac {
            acc.jp -= w * (g * dfn_dp.transpose() + fnorm * hm);
            acc.jv -= w * g * dfn_dv.transpose();
        }
        if matches!(self.law.friction, WallFriction::Frictionless) || fnorm < 0.0 {
            return;
        }
        let q = g.dot(&g);
        let s = psid;
        let vt = v - (s / q) * g;
        match self.law.friction {
            WallFriction::Frictionless => {}
            WallFriction::Coulomb { coefficient: mu, slip_velocity: eps } => {
                let m = (vt.dot(&vt) + eps * eps).sqrt();
                acc.f -= w * mu * fnorm * vt / m;
                if jac {
                    let (dvt_dp, dvt_dv) = tangential_jacobians(&g, &hm, &hv, q, s);
                    let dir = M3::identity() / m - vt * vt.transpose() / (m * m * m);
                    acc.jp -= w * mu * (vt / m * dfn_dp.transpose() + fnorm * dir * dvt_dp);
                    acc.jv -= w * mu * (vt / m * dfn_dv.transpose() + fnorm * dir * dvt_dv);
                }
            }
            WallFriction::NoSlip { drag, activation_depth } => {
                let (chi, dchi) = smoothstep(psi / activation_depth);
                acc.f -= w * drag * chi * vt;
                if jac {
                    let (dvt_dp, dvt_dv) = tangential_jacobians(&g, &hm, &hv, q, s);
                    acc.jp -= w * drag * (vt * (dchi / activation_depth) * g.transpose() + chi * dvt_dp);
                    acc.jv -= w * drag * chi * dvt_dv;
                }
            }
        }
    }

    /// [`Self::forces`] checking every point, without culling: the reference the culled
    /// pass must reproduce bit for bit (tests, benchmarks).
    #[doc(hidden)]
    pub fn forces_full(
        &self,
        body: &FluidBody,
        kin: &TankKinematics,
        e: &[f64],
        edot: &[f64],
        out: &mut [f64],
        mut jacobians: Option<&mut Vec<PointJacobian>>,
    ) -> ContactLoad {
        let mut load = ContactLoad::default();
        let a_mat = kin.rotation;
        let at = a_mat.transpose();
        let rt = Vector3::from(kin.position);
        let w = Vector3::from(kin.angular_velocity);
        let wt = w.cross_matrix();
        let mut hits = Vec::new();
        if let Some(j) = jacobians.as_mut() {
            j.clear();
        }
        for (k, pt) in self.points.iter().enumerate() {
            let (r, rd) = self.point_state(body, k, e, edot);
            let d = r - rt;
            let p = at * d;
            let (capacity, reach) = self.adhesion(pt);
            self.geometry.hits_within([p[0], p[1], p[2]], &pt.sides, reach, &mut hits);
            if hits.is_empty() {
                continue;
            }
            let v = at * (rd - Vector3::from(kin.velocity) - w.cross(&d));
            let (fk, jp, jv) = self.point_force(&hits, &v, pt.weight, capacity);
            let f = a_mat * fk;
            load.active += 1;
            load.max_penetration = hits.iter().fold(load.max_penetration, |m, h| m.max(h.psi));
            let nodes = &body.mesh.elements[pt.element];
            for a in 0..N_SHAPE {
                let g = 3 * (4 * nodes[a / 4] + a % 4);
                for i in 0..3 {
                    out[g + i] += pt.shape[a] * f[i];
                }
            }
            let m = d.cross(&(-f));
            for i in 0..3 {
                load.force[i] -= f[i];
                load.moment[i] += m[i];
            }
            if let Some(j) = jacobians.as_mut() {
                let dv = a_mat * jv * at;
                let dp = a_mat * jp * at - dv * wt;
                j.push(PointJacobian { point: k, d_position: dp, d_velocity: dv, force: f, arm: d });
            }
        }
        load
    }

    /// Tank-frame contact force at one point and its Jacobians ∂F/∂p, ∂F/∂v: the sum of
    /// [`Self::add_hit`] over its walls.
    fn point_force(&self, hits: &[WallHit], v: &Vector3<f64>, w: f64, capacity: f64) -> (Vector3<f64>, M3, M3) {
        let mut acc = PointAcc { hits: 0, f: Vector3::zeros(), jp: M3::zeros(), jv: M3::zeros() };
        for h in hits {
            self.add_hit(&mut acc, h, v, w, capacity, true);
        }
        (acc.f, acc.jp, acc.jv)
    }
}

/// ∂v_t/∂p and ∂v_t/∂v of v_t = v − (s/q) ∇ψ, s = ∇ψ·v, q = |∇ψ|² (as in `point_force`).
fn tangential_jacobians(g: &Vector3<f64>, hm: &M3, hv: &Vector3<f64>, q: f64, s: f64) -> (M3, M3) {
    let dvt_dv = M3::identity() - g * g.transpose() / q;
    let hg = hm * g;
    let dvt_dp = -(g * hv.transpose() / q + (s / q) * hm - (2.0 * s / (q * q)) * g * hg.transpose());
    (dvt_dp, dvt_dv)
}

/// Cull data of one face from its points (`pts`, in the order of [`WallContact::new`]:
/// point i·ppe + j at the i-th Gauss abscissa along one face direction and the j-th along
/// the other).
fn face_cull(pts: &[ContactPoint], start: usize, element: usize, ppe: usize) -> FaceCull {
    let cell = |members: &dyn Fn(usize, usize) -> bool| {
        let mut c = CullCell { mask: 0, lo: [f64::INFINITY; N_SHAPE], hi: [f64::NEG_INFINITY; N_SHAPE] };
        for i in 0..ppe {
            for j in 0..ppe {
                if members(i, j) {
                    let k = i * ppe + j;
                    c.mask |= 1 << k;
                    for a in 0..N_SHAPE {
                        c.lo[a] = c.lo[a].min(pts[k].shape[a]);
                        c.hi[a] = c.hi[a].max(pts[k].shape[a]);
                    }
                }
            }
        }
        c
    };
    let mut cells = vec![cell(&|_, _| true)];
    if ppe > 1 {
        for bi in 0..2 {
            for bj in 0..2 {
                cells.push(cell(&|i, j| 2 * i / ppe == bi && 2 * j / ppe == bj));
            }
        }
    }
    let mut used = 0u32;
    for a in 0..N_SHAPE {
        if cells[0].lo[a] != 0.0 || cells[0].hi[a] != 0.0 {
            used |= 1 << a;
        }
    }
    // the rounding of the 8-term sums (each |S_ka| < 2) is far below 1e-14
    let eta = pts.iter().fold(0.0f64, |m, p| m.max(((0..8).map(|n| p.shape[4 * n]).sum::<f64>() - 1.0).abs())) + 1e-14;
    let cullable = eta < 1e-10 && pts.iter().all(|p| p.sides == pts[0].sides);
    FaceCull { start, len: pts.len(), element, used, eta, cullable, candidate: cullable, cells }
}

/// Scatter point Jacobians into a dense global matrix (tests and small problems):
/// `kr[i*n + j] += ∂Q_i/∂e_j`, `kv` likewise for ė.
pub fn dense_jacobians(contact: &WallContact, body: &FluidBody, jac: &[PointJacobian], kr: &mut [f64], kv: &mut [f64]) {
    let n = body.n_coords();
    for pj in jac {
        let pt = &contact.points[pj.point];
        let nodes = &body.mesh.elements[pt.element];
        for a in 0..N_SHAPE {
            let ga = 3 * (4 * nodes[a / 4] + a % 4);
            for b in 0..N_SHAPE {
                let gb = 3 * (4 * nodes[b / 4] + b % 4);
                let nn = pt.shape[a] * pt.shape[b];
                for i in 0..3 {
                    for j in 0..3 {
                        kr[(ga + i) * n + gb + j] += nn * pj.d_position[(i, j)];
                        kv[(ga + i) * n + gb + j] += nn * pj.d_velocity[(i, j)];
                    }
                }
            }
        }
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constitutive::{Fluid, Rheology};
    use crate::element::QuadratureOptions;
    use crate::mesh::box_mesh;
    use crate::rng::Rng;
    use crate::tank::{Bulkhead, TankShape};
    use nalgebra::Rotation3;

    /// The liquid column of depth H (mass ρH per unit area) resting on the wall spring,
    /// m ψ̈ = m g − k_p ψ − c_p |ψ| ψ̇, nudged from its equilibrium ψ = δ_e: the logarithmic
    /// decrement of its free oscillation gives back the damping ratio the law was built with.
    #[test]
    fn the_wall_damping_ratio_is_the_damping_ratio_of_the_liquid_column_on_the_wall() {
        let (rho, g, depth) = (998.0, 9.81, 0.132);
        let m = rho * depth;
        let law0 = WallContactLaw::default_for(rho, g, depth);
        for zeta in [WALL_DAMPING_RATIO, 0.3] {
            let law = law0.with_damping_ratio(zeta, rho, g, depth).unwrap();
            let (k, c) = (law.stiffness, law.damping);
            let delta_e = m * g / k;
            let rhs = |psi: f64, v: f64| g - (k * psi + c * psi.abs() * v) / m;
            let (mut psi, mut v, h) = (1.001 * delta_e, 0.0, 1e-6);
            let mut peaks = Vec::new();
            let mut last_v: f64 = 0.0;
            for _ in 0..200_000 {
                let k1 = (v, rhs(psi, v));
                let k2 = (v + 0.5 * h * k1.1, rhs(psi + 0.5 * h * k1.0, v + 0.5 * h * k1.1));
                let k3 = (v + 0.5 * h * k2.1, rhs(psi + 0.5 * h * k2.0, v + 0.5 * h * k2.1));
                let k4 = (v + h * k3.1, rhs(psi + h * k3.0, v + h * k3.1));
                psi += h / 6.0 * (k1.0 + 2.0 * k2.0 + 2.0 * k3.0 + k4.0);
                v += h / 6.0 * (k1.1 + 2.0 * k2.1 + 2.0 * k3.1 + k4.1);
                if last_v > 0.0 && v <= 0.0 {
                    peaks.push(psi - delta_e);
                }
                last_v = v;
            }
            let d = (peaks[0] / peaks[1]).ln();
            let measured = d / (4.0 * std::f64::consts::PI * std::f64::consts::PI + d * d).sqrt();
            assert!((measured - zeta).abs() < 0.01 * zeta, "ζ_w = {zeta}: measured {measured}");
        }
        assert_eq!(law0.damping, law0.with_damping_ratio(WALL_DAMPING_RATIO, rho, g, depth).unwrap().damping);
        let e = law0.with_damping_ratio(-0.1, rho, g, depth).unwrap_err().to_string();
        assert!(e.contains("wall_damping_ratio") && e.contains("[0, 10]"), "{e}");
    }

    fn setup(friction: WallFriction) -> (FluidBody, WallContact, TankKinematics, Vec<f64>, Vec<f64>) {
        // a slightly smaller tank and a bulkhead: many points penetrate
        setup_in(friction, TankShape::Box { min: [-0.29, -0.195, 0.004], max: [0.29, 0.195, 0.29] }, 0.0)
    }

    /// The contact of a 2×2×1 box of liquid (0.6 × 0.4 × 0.3 m, its top the free surface)
    /// in tank `shape` with a bulkhead at x = 0.01 m, in a moving tank frame, with noisy
    /// coordinates and velocities.
    fn setup_in(
        friction: WallFriction,
        shape: TankShape,
        tension_capacity: f64,
    ) -> (FluidBody, WallContact, TankKinematics, Vec<f64>, Vec<f64>) {
        let mesh = box_mesh([-0.3, -0.2, 0.0], [0.6, 0.4, 0.3], [2, 2, 1]).unwrap();
        let fluid = Fluid::new(1000.0, Rheology::Newtonian { viscosity: 1.0 }, 1e5).unwrap();
        let body = FluidBody::new(mesh, fluid, QuadratureOptions::default()).unwrap();
        let geo = TankGeometry::new(shape, vec![Bulkhead { x: 0.01, thickness: 0.01 }]).unwrap();
        let law = WallContactLaw {
            stiffness: 1e6,
            damping: 2e5,
            friction,
            points_per_edge: 2,
            point_rule: ContactPointRule::Gauss,
            tension_capacity,
        };
        let contact = WallContact::new(&body, geo, law).unwrap();
        let rot = *Rotation3::from_euler_angles(0.1, -0.2, 0.3).matrix();
        let kin = TankKinematics {
            position: [1.0, -0.5, 0.2],
            rotation: rot,
            velocity: [3.0, 0.2, -0.1],
            angular_velocity: [0.3, -0.2, 0.5],
        };
        let mut rng = Rng::new(3);
        // fluid coordinates: reference placed into the tank frame, plus noise
        let e0 = body.reference_coordinates();
        let mut e = vec![0.0; e0.len()];
        for (s, (x, y)) in e0.chunks_exact(3).zip(e.chunks_exact_mut(3)).enumerate() {
            let v = rot * Vector3::new(x[0], x[1], x[2]);
            let v = if s % 4 == 0 { v + Vector3::from(kin.position) } else { v };
            for i in 0..3 {
                y[i] = v[i] + 0.002 * rng.uniform();
            }
        }
        let edot: Vec<f64> = e.iter().map(|_| 0.3 * rng.uniform()).collect();
        (body, contact, kin, e, edot)
    }

    /// The point Jacobians `jac` of `contact` at `(e, edot)`, assembled, equal central
    /// differences of its forces (h = 1e-7) to 1e-6 of their largest entry.
    fn assert_jacobians_match_fd(
        contact: &WallContact,
        body: &FluidBody,
        kin: &TankKinematics,
        e: &[f64],
        edot: &[f64],
        jac: &[PointJacobian],
        label: &str,
    ) {
        let n = body.n_coords();
        let mut kr = vec![0.0; n * n];
        let mut kv = vec![0.0; n * n];
        dense_jacobians(contact, body, jac, &mut kr, &mut kv);
        for (which, k) in [(0, &kr), (1, &kv)] {
            let scale = k.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            let mut worst = 0.0f64;
            for d in 0..n {
                let h = 1e-7;
                let (mut xp, mut xm) =
                    if which == 0 { (e.to_vec(), e.to_vec()) } else { (edot.to_vec(), edot.to_vec()) };
                xp[d] += h;
                xm[d] -= h;
                let (mut qp, mut qm) = (vec![0.0; n], vec![0.0; n]);
                if which == 0 {
                    contact.forces(body, kin, &xp, edot, &mut qp, None);
                    contact.forces(body, kin, &xm, edot, &mut qm, None);
                } else {
                    contact.forces(body, kin, e, &xp, &mut qp, None);
                    contact.forces(body, kin, e, &xm, &mut qm, None);
                }
                for r in 0..n {
                    let fd = (qp[r] - qm[r]) / (2.0 * h);
                    worst = worst.max((fd - k[r * n + d]).abs());
                }
            }
            assert!(worst / scale < 1e-6, "{label} {which}: {:.2e}", worst / scale);
        }
    }

    /// Stored energy: d/ds U(e + s δ) = −(elastic contact force)·δ for a random δ (seed
    /// `seed`, entries up to 1 mm), by central differences of step `s` with the damping off,
    /// to 1e-6 relative.
    fn assert_stored_energy_is_the_elastic_potential(
        c: &WallContact,
        body: &FluidBody,
        kin: &TankKinematics,
        e: &[f64],
        seed: u64,
        s: f64,
    ) {
        let c0 = WallContact { law: WallContactLaw { damping: 0.0, ..c.law }, ..c.clone() };
        let mut rng = Rng::new(seed);
        let d: Vec<f64> = (0..e.len()).map(|_| rng.uniform() * 1e-3).collect();
        let zero = vec![0.0; e.len()];
        let mut f = vec![0.0; e.len()];
        c0.forces(body, kin, e, &zero, &mut f, None);
        let plus: Vec<f64> = e.iter().zip(&d).map(|(x, y)| x + s * y).collect();
        let minus: Vec<f64> = e.iter().zip(&d).map(|(x, y)| x - s * y).collect();
        let du = (c0.stored_energy(body, kin, &plus) - c0.stored_energy(body, kin, &minus)) / (2.0 * s);
        let fd: f64 = f.iter().zip(&d).map(|(x, y)| x * y).sum();
        assert!((du + fd).abs() < 1e-6 * fd.abs().max(1e-9), "dU = {du}, -F.d = {}", -fd);
    }

    #[test]
    fn contact_jacobians_match_finite_differences() {
        for friction in [
            WallFriction::Frictionless,
            WallFriction::Coulomb { coefficient: 0.4, slip_velocity: 0.05 },
            WallFriction::NoSlip { drag: 2e3, activation_depth: 0.003 },
        ] {
            let (body, contact, kin, e, edot) = setup(friction);
            let n = body.n_coords();
            let mut q = vec![0.0; n];
            let mut jac = Vec::new();
            let load = contact.forces(&body, &kin, &e, &edot, &mut q, Some(&mut jac));
            assert!(load.active > 10, "active {}", load.active);
            assert_jacobians_match_fd(&contact, &body, &kin, &e, &edot, &jac, &format!("{friction:?}"));
        }
    }

    #[test]
    fn tank_load_is_equal_and_opposite_to_the_fluid_load() {
        let (body, contact, kin, e, edot) = setup(WallFriction::Coulomb { coefficient: 0.3, slip_velocity: 0.05 });
        let mut q = vec![0.0; body.n_coords()];
        let load = contact.forces(&body, &kin, &e, &edot, &mut q, None);
        // the resultant of the generalized forces on position coordinates (sum of N_a over
        // position functions is 1) equals minus the tank force
        let mut f = [0.0; 3];
        for (s, x) in q.chunks_exact(3).enumerate() {
            if s % 4 == 0 {
                for i in 0..3 {
                    f[i] += x[i];
                }
            }
        }
        for i in 0..3 {
            assert!((f[i] + load.force[i]).abs() < 1e-9 * load.force.iter().fold(1.0f64, |m, x| m.max(x.abs())));
        }
        assert!(load.max_penetration > 0.003);
    }

    #[test]
    fn points_cover_the_boundary_area() {
        let mesh = box_mesh([0.0; 3], [0.6, 0.4, 0.3], [3, 2, 2]).unwrap();
        let body = FluidBody::new(
            mesh,
            Fluid::new(1000.0, Rheology::Newtonian { viscosity: 1.0 }, 1e5).unwrap(),
            QuadratureOptions::default(),
        )
        .unwrap();
        let geo = TankGeometry::new(TankShape::Box { min: [0.0; 3], max: [0.6, 0.4, 0.5] }, vec![]).unwrap();
        let c = WallContact::new(&body, geo, WallContactLaw::default_for(1000.0, 9.81, 0.3)).unwrap();
        let area: f64 = c.points.iter().map(|p| p.weight).sum();
        assert!((area - 2.0 * (0.6 * 0.4 + 0.6 * 0.3 + 0.4 * 0.3)).abs() < 1e-12);
    }

    #[test]
    fn lobatto_points_cover_the_area_and_hold_every_boundary_node() {
        let mesh = box_mesh([0.0; 3], [0.6, 0.4, 0.3], [3, 2, 2]).unwrap();
        let fluid = Fluid::new(1000.0, Rheology::Newtonian { viscosity: 1.0 }, 1e5).unwrap();
        let body = FluidBody::new(mesh, fluid, QuadratureOptions::default()).unwrap();
        let geo = TankGeometry::new(TankShape::Box { min: [0.0; 3], max: [0.6, 0.4, 0.5] }, vec![]).unwrap();
        let law =
            WallContactLaw { point_rule: ContactPointRule::Lobatto, ..WallContactLaw::default_for(1000.0, 9.81, 0.3) };
        let c = WallContact::new(&body, geo.clone(), law).unwrap();
        let area: f64 = c.points.iter().map(|p| p.weight).sum();
        assert!((area - 2.0 * (0.6 * 0.4 + 0.6 * 0.3 + 0.4 * 0.3)).abs() < 1e-12);
        // every node on the boundary is a contact point (Gauss points never are)
        let e = body.reference_coordinates();
        let pts: Vec<Vector3<f64>> = (0..c.points.len()).map(|k| c.point_position(&body, k, &e)).collect();
        let on_boundary =
            |p: &[f64; 12]| (0..3).any(|d| p[d].abs() < 1e-12 || (p[d] - [0.6, 0.4, 0.3][d]).abs() < 1e-12);
        for n in body.mesh.nodes.iter().filter(|n| on_boundary(n)) {
            let x = Vector3::new(n[0], n[1], n[2]);
            assert!(pts.iter().any(|p| (p - x).norm() < 1e-12), "node {x:?} is no contact point");
        }
        let gauss = WallContact::new(&body, geo, WallContactLaw::default_for(1000.0, 9.81, 0.3)).unwrap();
        let corner = Vector3::zeros();
        assert!((0..gauss.points.len()).all(|k| (gauss.point_position(&body, k, &e) - corner).norm() > 1e-3));
        // one point per edge cannot hold both edges
        let one = WallContactLaw { points_per_edge: 1, ..law };
        assert!(one.validate().unwrap_err().to_string().contains("contact.points_per_edge"));
    }

    #[test]
    fn containment_finds_the_deepest_site_and_stored_energy_is_the_spring_potential() {
        let (body, c, kin, e, _) = setup(WallFriction::Frictionless);
        // the tank is smaller than the mesh: nodes at the corners stick out by 10 mm in x
        let b = c.containment(&body, &kin, &e).expect("the setup penetrates");
        assert!(b.depth > 0.0 && b.depth.is_finite());
        // no site is deeper: every node checked against the same walls
        let at = kin.rotation.transpose();
        for n in 0..body.mesh.n_nodes() {
            let r = Vector3::new(e[12 * n], e[12 * n + 1], e[12 * n + 2]) - Vector3::from(kin.position);
            let p = at * r;
            let mut d = 0.0f64;
            c.geometry.for_each_hit([p[0], p[1], p[2]], &c.node_sides[n], |h| d = d.max(h.psi));
            assert!(d <= b.depth + 1e-15, "node {n} is {d} deep, deeper than {b:?}");
        }
        assert_stored_energy_is_the_elastic_potential(&c, &body, &kin, &e, 11, 1e-4);
        // a body far outside: reported, with an infinite depth for non-finite coordinates
        let mut nan = e.clone();
        nan[0] = f64::NAN;
        assert_eq!(c.containment(&body, &kin, &nan).map(|b| b.depth), Some(f64::INFINITY));
    }

    /// An adhesive wall: a tank 1.5 mm larger than the liquid on the −x, −y, −z sides and
    /// 0.5 mm on the +x, +y sides (the noise of [`setup_in`] is 0–2 mm) and p_a = 3 kPa with
    /// k_p = 1 MPa/m (s = 3 mm, reach 6 mm): with ±2 mm of noise, wetted points fall on
    /// every branch of the law.
    fn adhesive_setup(friction: WallFriction) -> (FluidBody, WallContact, TankKinematics, Vec<f64>, Vec<f64>) {
        setup_in(friction, TankShape::Box { min: [-0.3015, -0.2015, -0.0015], max: [0.3005, 0.2005, 0.35] }, 3e3)
    }

    #[test]
    fn the_normal_law_is_continuous_and_its_potential_is_its_integral() {
        let (k, c, pa) = (1e6, 2e5, 3e3);
        let s = pa / k;
        let f = |psi: f64, psid: f64| normal_force(k, c, pa, psi, psid).map_or(0.0, |x| x.0);
        for psid in [-0.5, 0.0, 0.3] {
            // continuous at the branch ends (value and, off the clamp, no jump)
            for psi in [0.0, -s, -2.0 * s] {
                assert!((f(psi + 1e-12, psid) - f(psi - 1e-12, psid)).abs() < 1e-5, "ψ = {psi}, ψ̇ = {psid}");
            }
        }
        assert_eq!(f(-s, 0.0), -pa);
        assert_eq!(f(-2.0 * s - 1e-9, 0.0), 0.0);
        // the suction never exceeds p_a, however fast the liquid leaves
        assert_eq!(f(1e-3, -100.0), -pa);
        // a unilateral wall: the old law, bit for bit
        for (psi, psid) in [(1e-3, 0.2), (2e-3, -0.01), (-1e-3, 0.0)] {
            let old = psi * (k + c * psid);
            let new = normal_force(k, c, 0.0, psi, psid);
            if old > 0.0 && psi > 0.0 {
                assert_eq!(new, Some((old, k + c * psid, c * psi)));
            } else {
                assert_eq!(new, None);
            }
        }
        // dU/dψ = f_n (damping off), central differences across the branches
        for i in 0..40 {
            let psi = -7e-3 + 8e-3 * i as f64 / 39.0 + 1.3e-6;
            let h = 1e-8;
            let du = (normal_potential(k, pa, psi + h) - normal_potential(k, pa, psi - h)) / (2.0 * h);
            let fe = normal_force(k, 0.0, pa, psi, 0.0).map_or(0.0, |x| x.0);
            assert!((du - fe).abs() < 1e-4 * pa, "ψ = {psi}: dU/dψ {du} vs f {fe}");
        }
        let e = WallContactLaw::default_for(1000.0, 9.81, 0.1).with_adhesion(-1.0, 1000.0, 9.81, 0.1).unwrap_err();
        assert!(e.to_string().contains("wall_adhesion") && e.to_string().contains("[0, 50]"), "{e}");
    }

    #[test]
    fn adhesive_contact_jacobians_match_finite_differences_and_energy() {
        for friction in [WallFriction::Frictionless, WallFriction::Coulomb { coefficient: 0.4, slip_velocity: 0.05 }] {
            let (body, contact, kin, e, edot) = adhesive_setup(friction);
            let n = body.n_coords();
            let mut q = vec![0.0; n];
            let mut jac = Vec::new();
            let load = contact.forces(&body, &kin, &e, &edot, &mut q, Some(&mut jac));
            // points on every branch: penetrating, held by suction, out of reach
            let at = kin.rotation.transpose();
            let (mut pushed, mut held) = (0, 0);
            for (k, pt) in contact.points.iter().enumerate() {
                let p = at * (contact.point_position(&body, k, &e) - Vector3::from(kin.position));
                contact.geometry.for_each_hit_with([p[0], p[1], p[2]], &pt.sides, false, contact.law.reach(), |h| {
                    if h.psi > 0.0 {
                        pushed += 1
                    } else if pt.wetted {
                        held += 1
                    }
                });
            }
            assert!(pushed > 3 && held > 3 && load.active > 6, "pushed {pushed}, held {held}");
            // the culled pass equals the full one, bit for bit
            let mut q_full = vec![0.0; n];
            let full = contact.forces_full(&body, &kin, &e, &edot, &mut q_full, None);
            assert_eq!(q, q_full);
            assert_eq!(load.force, full.force);
            assert_jacobians_match_fd(&contact, &body, &kin, &e, &edot, &jac, &format!("{friction:?}"));
        }
        let (body, c, kin, e, _) = adhesive_setup(WallFriction::Frictionless);
        assert_stored_energy_is_the_elastic_potential(&c, &body, &kin, &e, 5, 1e-5);
        // nothing is beyond the walls by the containment check (it ignores the reach)
        assert!(c.containment(&body, &kin, &e).is_none_or(|b| b.depth < 0.003));
    }
}
