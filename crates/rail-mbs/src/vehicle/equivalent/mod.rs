//! Equivalent mechanical (spring–mass / pendulum) slosh model of the liquid in a tank car:
//! the cheap middle between rigid lading and the ANCF continuum ([`super::fluid`]).
//!
//! # The liquid
//!
//! The tank is the car's cylinder (radius `R`, [`TankCarParams::tank_radius`]) with
//! half-ellipsoidal heads of depth [`EquivalentCargo::head_depth`] (0.5 m, as
//! [`super::build_fluid_train`]), overall length `tank_length`. `fill` is the liquid
//! **volume** fraction, exactly as for the ANCF cargo ([`super::FluidCargo::fill`],
//! `ancf_core::mesh::CylinderTankSpec::fill`): the liquid depth `h` follows from the tank
//! volume, so the liquid mass `M = ρ V` equals the ANCF mesh's at the same fill (tested).
//! At half fill `h = R`; elsewhere `h ≠ 2R·fill` (the ANCF run uses `2R·fill` only to
//! scale its penalty and wall laws). Bulkheads `(x, thickness)` split the liquid into
//! compartments, as `ancf_core::mesh::cylinder_tank_compartments`; each compartment gets
//! its own mode.
//!
//! Cross-section (notes `sloshing-validation-and-cosimulation.md` §1b): `cos α = (R − h)/R`,
//! free-surface half-width `w = R sin α`, segment area `A = (R²/2)(2α − sin 2α)`, centroid
//! depth below the axis `d = 4R sin³α / (3(2α − sin 2α))`. Each compartment's volume,
//! centroid and equivalent length `L_c = V_c/A` (the length of the prismatic trough of the
//! same volume and section) include the liquid in the heads (closed forms below).
//!
//! # Modes (notes §3)
//!
//! * **Longitudinal** (tank x, braking): the first mode of the rectangular tank of length
//!   `L_c` and the trough's long-wave depth `h_eq = A/(2w)`:
//!   `ω² = (πg/L_c) tanh(π h_eq/L_c)`, `m₁ = M_c · 8 tanh(π h_eq/L_c) / (π³ h_eq/L_c)`,
//!   `m₀ = M_c − m₁`; both at the compartment's liquid centroid.
//! * **Lateral** (tank y, curving): a pendulum hinged on the tank axis (the wall pressure
//!   of a circular section passes through the axis), `l₁ = R/λ`, `ω² = λg/R`,
//!   `m₁ = M_c d_c λ/R` (static-tilt matching `m₁ l₁ = M_c d_c`, `d_c` the compartment's
//!   centroid depth, equal to the segment's `d` = `BM` for flat ends), `m₀ = M_c − m₁` on the
//!   axis. `λ(h/2R) = ω₁²R/g` comes from [`cylinder_lambda`].
//!
//! **One axis per scene.** The two families are not one model: for a long half-full tank
//! `m₁ₓ ≈ 0.8 M` and `m₁ᵧ ≈ 0.58 M`, so modelling both as separate bodies would count more
//! than the whole liquid as sloshing (`m₁ₓ + m₁ᵧ > M`) and misplace its static centre of
//! mass. A scene therefore picks [`SloshAxis::Longitudinal`] (braking) or
//! [`SloshAxis::Lateral`] (curving); the other direction is carried rigidly. Scenes that
//! excite both need the ANCF model.
//!
//! # Damping
//!
//! Viscous Stokes-layer damping of the first mode in the shallow-water form used for tuned
//! liquid dampers (Sun/Fujino 1992 after Miles 1967; notes §1d, marked **[mem]** there: from
//! memory, not checked against the source): `ζ = (1/(2h)) √(ν/(2ω)) (1 + 2h/b)` with
//! `h = h_eq`, `b` the breadth across the motion (`2w` for longitudinal sloshing, `L_c` for
//! lateral), `ν = μ/ρ`. For Bingham, Oldroyd and Casson liquids `μ` is the plastic
//! viscosity and **the yield stress is ignored**; Herschel–Bulkley uses its consistency `K`
//! (the apparent viscosity at 1 s⁻¹). The boundary-layer formula needs the Stokes layer
//! `δ = √(2ν/ω)` thin compared with `h`. For the heavy crude of seed 000 (ν = 0.1 m²/s) in
//! the half-full car tank `δ` is 0.26 m (lateral, ζ = 0.07) to 0.47 m (longitudinal,
//! ζ = 0.18) against `h_eq` = 1.18 m: the formula is only a rough indication there, and for
//! still more viscous liquids it would exceed critical damping, so `ζ` is capped at 1
//! (critically damped) — a crude bound, not a model of a creeping liquid. A yield-stress
//! liquid that does not yield at all moves rigidly; this model does not represent that.
//!
//! # Multibody realisation
//!
//! Per car and compartment a slosh body of mass `m₁` (inertia `m₁ (0.2 m)²` about each
//! axis) sits at its rest position in the tank and is tied to the tank body by a
//! [`Bushing`]: stiffness `m₁ ω²` and damping `2ζ m₁ ω` along the slosh axis; stiff
//! (20 Hz relative to `m₁`, damping ratio 0.1) in the other two translations and in
//! rotation, so the implicit HHT steps of 1–4 ms stay accurate and stable. The bushing
//! carries the slosh body's weight as a preload in the stiff directions (the gravity
//! component along the slosh axis, e.g. on a grade, acts on the mode as it should). The
//! fixed masses `m₀` are added to the tank body as rigid lading at their mass-weighted
//! height (combined with any lading of the car), and their distributed pitch and yaw
//! inertia `Σ m₀ (x_c² + L_c²/12)` is added to the tank's; they are lumped at the tank's
//! mid-length, so asymmetric bulkheads shift the static centre of mass along x by
//! `Σ m₀ x_c / M_total` (zero for symmetric ones). The liquid has no roll inertia about
//! the axis (inviscid: notes §3), beyond `m₀ z₀²` of the lading.

use ancf_core::error::{AncfError, check_positive, invalid};
use ancf_core::mesh::CylinderTankSpec;
use ancf_core::{Fluid, Rheology};
use nalgebra::{Matrix3, Vector3};

use super::run::{
    Cargo, Observer, RunFailure, RunResult, SampleSink, TrainRecord, TrainRun, TrainScenario, build_train, drive,
    record_sample,
};
use super::tank_car::CarBodies;
use crate::integrator::{Hht, IntegratorError};
use crate::mbs::{BodyId, Bushing, Multibody, RigidBody};

mod modes;
pub use modes::*;

/// Which direction of the tank sloshes in the equivalent model (module docs: one per scene).
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum SloshAxis {
    /// Along the tank axis (x): braking and traction.
    Longitudinal,
    /// Across the tank (y): curving, lateral disturbances.
    Lateral,
}

impl SloshAxis {
    /// Index of the tank-frame axis (0 = x, 1 = y).
    pub fn index(self) -> usize {
        match self {
            SloshAxis::Longitudinal => 0,
            SloshAxis::Lateral => 1,
        }
    }
}

/// Liquid cargo of every car modelled by its equivalent spring–mass / pendulum system.
#[derive(Debug, Clone, PartialEq)]
pub struct EquivalentCargo {
    /// Liquid density ρ, kg/m³.
    pub density: f64,
    /// Dynamic (plastic) viscosity μ, Pa·s (yield stresses are ignored).
    pub viscosity: f64,
    /// Liquid volume as a fraction of the tank volume (as [`super::FluidCargo::fill`]).
    pub fill: f64,
    /// Bulkheads `(x, thickness)` in the tank frame, m.
    pub bulkheads: Vec<(f64, f64)>,
    /// The sloshing direction.
    pub axis: SloshAxis,
    /// Depth of each half-ellipsoidal head, m. Default [`crate::vehicle::TANK_HEAD_DEPTH`] (as the ANCF cargo).
    pub head_depth: f64,
}

impl EquivalentCargo {
    /// Cargo with the heads of the ANCF cargo (0.5 m deep).
    pub fn new(density: f64, viscosity: f64, fill: f64, bulkheads: Vec<(f64, f64)>, axis: SloshAxis) -> Self {
        Self { density, viscosity, fill, bulkheads, axis, head_depth: crate::vehicle::TANK_HEAD_DEPTH }
    }

    /// Cargo of an ANCF fluid's density and (plastic) viscosity (module docs).
    pub fn from_fluid(fluid: &Fluid, fill: f64, bulkheads: Vec<(f64, f64)>, axis: SloshAxis) -> Self {
        let mu = match fluid.rheology {
            Rheology::Newtonian { viscosity }
            | Rheology::Bingham { viscosity, .. }
            | Rheology::Oldroyd { viscosity, .. }
            | Rheology::Casson { viscosity, .. } => viscosity,
            Rheology::HerschelBulkley { consistency, .. } => consistency,
        };
        Self::new(fluid.density, mu, fill, bulkheads, axis)
    }

    /// Checks the fields; errors name the field and the allowed range.
    pub fn validate(&self) -> Result<(), AncfError> {
        if !(self.density.is_finite() && (100.0..=20_000.0).contains(&self.density)) {
            return Err(invalid("density", self.density, "100 to 20000 kg/m^3"));
        }
        if !(self.viscosity.is_finite() && (0.0..=1e5).contains(&self.viscosity)) {
            return Err(invalid("viscosity", self.viscosity, "0 to 1e5 Pa s"));
        }
        ancf_core::mesh::check_fill(self.fill)?;
        if !(self.head_depth.is_finite() && self.head_depth >= 0.0) {
            return Err(invalid("head_depth", self.head_depth, "finite, >= 0 m"));
        }
        Ok(())
    }

    /// The equivalent model of this cargo in the tank of `car` under gravity `g`.
    pub fn model(&self, car: &super::TankCarParams, g: f64) -> Result<EquivalentModel, AncfError> {
        self.validate()?;
        check_positive("gravity", g)?;
        let (r, hd) = (car.tank_radius, self.head_depth);
        if hd > r {
            return Err(invalid("head_depth", hd, &format!("0 to the tank radius {r} m")));
        }
        let shell = car.tank_length - 2.0 * hd;
        check_positive("tank_length - 2 head_depth (shell length)", shell)?;
        let spec = CylinderTankSpec {
            length: shell,
            radius: r,
            head_depth: hd,
            fill: self.fill,
            n_length: 1,
            n_width: 2,
            n_height: 1,
            grading: 1.0,
        };
        spec.validate()?;
        let depth = spec.liquid_depth();
        let fraction = depth / (2.0 * r);
        let (lo, hi) = DEPTH_FRACTION_RANGE;
        if !(lo..=hi).contains(&fraction) {
            return Err(invalid(
                "fill",
                self.fill,
                &format!("a volume fraction whose liquid depth is {lo} to {hi} of the diameter (here {fraction:.4})"),
            ));
        }
        let seg = segment(r, depth)?;
        let lam = cylinder_lambda(fraction)?;
        let nu = self.viscosity / self.density;
        let h_eq = seg.area / (2.0 * seg.half_width);
        let mut compartments = Vec::new();
        for (x0, x1, heads) in compartment_ends(shell, &self.bulkheads)? {
            let c = compartment(r, hd, shell, depth, &seg, (x0, x1), heads);
            compartments.push(Compartment { mass: self.density * c.0, centroid: c.1, length: c.0 / seg.area });
        }
        let mut modes = Vec::new();
        for (i, c) in compartments.iter().enumerate() {
            let [xc, _, zc] = c.centroid;
            let mode = match self.axis {
                SloshAxis::Longitudinal => {
                    let (omega, m1) = rectangular_mode(c.length, h_eq, c.mass, g)?;
                    SloshMode {
                        compartment: i,
                        mass: m1,
                        fixed_mass: c.mass - m1,
                        omega,
                        damping_ratio: stokes_damping_ratio(nu, omega, h_eq, 2.0 * seg.half_width),
                        position: [xc, 0.0, zc],
                        fixed_position: [xc, 0.0, zc],
                        pendulum_length: g / (omega * omega),
                    }
                }
                SloshAxis::Lateral => {
                    let l1 = r / lam;
                    let (omega, m1) = cylinder_lateral_mode(r, lam, c.mass, -zc, g);
                    SloshMode {
                        compartment: i,
                        mass: m1,
                        fixed_mass: c.mass - m1,
                        omega,
                        damping_ratio: stokes_damping_ratio(nu, omega, h_eq, c.length),
                        position: [xc, 0.0, -l1],
                        fixed_position: [xc, 0.0, 0.0],
                        pendulum_length: l1,
                    }
                }
            };
            modes.push(mode);
        }
        let mass = compartments.iter().map(|c| c.mass).sum::<f64>();
        let centroid =
            [0, 1, 2].map(|k| compartments.iter().map(|c| c.mass * c.centroid[k]).sum::<f64>() / mass.max(1e-300));
        Ok(EquivalentModel {
            axis: self.axis,
            depth,
            depth_fraction: fraction,
            lambda: lam,
            segment: seg,
            equivalent_depth: h_eq,
            mass,
            centroid,
            compartments,
            modes,
        })
    }
}

/// Axial extent of each compartment's liquid: `(x0, x1, [rear head, front head])`, the ends
/// at the shell's tangent planes or the bulkhead faces.
fn compartment_ends(shell: f64, bulkheads: &[(f64, f64)]) -> Result<Vec<(f64, f64, [bool; 2])>, AncfError> {
    let half = 0.5 * shell;
    let mut out = Vec::new();
    let mut lo = (-half, true);
    for (i, &(x, t)) in bulkheads.iter().enumerate() {
        check_positive(&format!("bulkheads[{i}].thickness"), t)?;
        if !(x.is_finite() && x - t / 2.0 > -half && x + t / 2.0 < half) {
            return Err(invalid(&format!("bulkheads[{i}].x"), x, &format!("within the shell, in ({}, {half})", -half)));
        }
        if x - t / 2.0 <= lo.0 && !lo.1 {
            return Err(invalid(&format!("bulkheads[{i}].x"), x, "increasing and not overlapping"));
        }
        out.push((lo.0, x - t / 2.0, [lo.1, false]));
        lo = (x + t / 2.0, false);
    }
    out.push((lo.0, half, [lo.1, true]));
    Ok(out)
}

/// Volume and centroid (tank frame) of the liquid of one compartment: the shell part
/// `[x0, x1]` plus the half-ellipsoidal heads it touches.
///
/// A head of depth `a` is the half-sphere of radius `R` scaled by `s = a/R` along x; below
/// the free surface `z_s = h − R` it holds `V = s (π/2) ∫ρ² dz`, its first moments beyond the
/// tangent plane are `s² (2/3) ∫ρ³ dz` (x; half-disks of radius ρ have their centroid at
/// `4ρ/3π`) and `s (π/2) ∫ z ρ² dz` (z), with `ρ² = R² − z²` and the integrals from `−R`
/// to `z_s` in closed form.
fn compartment(
    r: f64,
    a: f64,
    shell: f64,
    depth: f64,
    seg: &Segment,
    (x0, x1): (f64, f64),
    heads: [bool; 2],
) -> (f64, [f64; 3]) {
    use std::f64::consts::PI;
    let zs = depth - r;
    let s = a / r;
    let int_rho2 = r * r * (zs + r) - (zs.powi(3) + r.powi(3)) / 3.0;
    let p3 = |t: f64| {
        let c = (t / r).clamp(-1.0, 1.0);
        (t / 8.0) * (5.0 * r * r - 2.0 * t * t) * (r * r - t * t).max(0.0).sqrt() + 3.0 * r.powi(4) / 8.0 * c.asin()
    };
    let int_rho3 = p3(zs) - p3(-r);
    let int_zrho2 = (0.5 * r * r * zs * zs - 0.25 * zs.powi(4)) - (0.5 * r.powi(4) - 0.25 * r.powi(4));
    let vh = s * 0.5 * PI * int_rho2;
    let xh = s * s * (2.0 / 3.0) * int_rho3;
    let zh = s * 0.5 * PI * int_zrho2;
    let vs = seg.area * (x1 - x0);
    let (mut v, mut mx, mut mz) = (vs, vs * 0.5 * (x0 + x1), -seg.centroid_depth * vs);
    for (present, sign) in [(heads[0], -1.0), (heads[1], 1.0)] {
        if present && a > 0.0 {
            v += vh;
            mx += sign * (0.5 * shell * vh + xh);
            mz += zh;
        }
    }
    (v, [mx / v, 0.0, mz / v])
}

/// The liquid of one compartment.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Compartment {
    /// Liquid mass `M_c`, kg.
    pub mass: f64,
    /// Liquid centroid at rest, tank frame, m.
    pub centroid: [f64; 3],
    /// Equivalent length `L_c = V_c/A`, m.
    pub length: f64,
}

/// One sloshing mode (one compartment) of the equivalent model.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SloshMode {
    /// Index of its compartment.
    pub compartment: usize,
    /// Sloshing mass `m₁`, kg.
    pub mass: f64,
    /// Fixed (rigidly carried) mass `m₀ = M_c − m₁`, kg.
    pub fixed_mass: f64,
    /// Natural angular frequency ω₁, rad/s.
    pub omega: f64,
    /// Viscous damping ratio ζ (≤ 1).
    pub damping_ratio: f64,
    /// Rest position of `m₁`, tank frame, m.
    pub position: [f64; 3],
    /// Position of `m₀`, tank frame, m.
    pub fixed_position: [f64; 3],
    /// Equivalent pendulum length `l₁ = g/ω²`, m (`R/λ` for the lateral pendulum).
    pub pendulum_length: f64,
}

/// The equivalent model of one car's liquid.
#[derive(Debug, Clone, PartialEq)]
pub struct EquivalentModel {
    /// Sloshing direction.
    pub axis: SloshAxis,
    /// Liquid depth `h`, m.
    pub depth: f64,
    /// `h/2R`.
    pub depth_fraction: f64,
    /// `λ(h/2R)` of the circular section.
    pub lambda: f64,
    /// The liquid cross-section.
    pub segment: Segment,
    /// Long-wave depth `h_eq = A/(2w)`, m.
    pub equivalent_depth: f64,
    /// Liquid mass `M`, kg.
    pub mass: f64,
    /// Liquid centroid at rest, tank frame, m.
    pub centroid: [f64; 3],
    /// Compartments, rear to front.
    pub compartments: Vec<Compartment>,
    /// One mode per compartment.
    pub modes: Vec<SloshMode>,
}

impl EquivalentModel {
    /// Total fixed mass `Σ m₀`, kg.
    pub fn fixed_mass(&self) -> f64 {
        self.modes.iter().map(|m| m.fixed_mass).sum()
    }

    /// Total sloshing mass `Σ m₁`, kg.
    pub fn sloshing_mass(&self) -> f64 {
        self.modes.iter().map(|m| m.mass).sum()
    }

    /// Liquid centre of mass (tank frame) with the slosh masses at `positions` (tank frame):
    /// `(Σ m₀ r₀ + Σ m₁ r₁)/M`.
    pub fn center_of_mass(&self, positions: &[[f64; 3]]) -> [f64; 3] {
        [0, 1, 2].map(|k| {
            self.modes
                .iter()
                .zip(positions)
                .map(|(m, p)| m.fixed_mass * m.fixed_position[k] + m.mass * p[k])
                .sum::<f64>()
                / self.mass
        })
    }

    /// Fixed masses as one rigid lading `(mass, height above the axis)` combined with `lading`.
    pub fn lading(&self, lading: Option<(f64, f64)>) -> (f64, f64) {
        let (ml, hl) = lading.unwrap_or((0.0, 0.0));
        let m = ml + self.fixed_mass();
        let mz = ml * hl + self.modes.iter().map(|s| s.fixed_mass * s.fixed_position[2]).sum::<f64>();
        (m, if m > 0.0 { mz / m } else { 0.0 })
    }
}

/// A slosh body tied to its tank (module docs). `at` is its rest position in the tank body's
/// frame (body origin = centre of mass); `tank` must already be in `mb`. Returns the body id.
pub fn add_slosh_body(
    mb: &mut Multibody,
    name: &str,
    tank: BodyId,
    at: Vector3<f64>,
    mode: &SloshMode,
    axis: SloshAxis,
) -> Result<BodyId, AncfError> {
    check_positive(&format!("{name} mass"), mode.mass)?;
    check_positive(&format!("{name} omega"), mode.omega)?;
    if !(mode.damping_ratio.is_finite() && (0.0..=1.0).contains(&mode.damping_ratio)) {
        return Err(invalid(&format!("{name} damping_ratio"), mode.damping_ratio, "0 to 1"));
    }
    let st = mb.initial_state(Some(tank));
    let arm = st.rotation * at;
    let inertia = mode.mass * SLOSH_BODY_GYRATION * SLOSH_BODY_GYRATION;
    let mut body = RigidBody::new(name, mode.mass, [inertia; 3], st.position + arm);
    body.orientation = st.rotation;
    body.velocity = st.velocity + st.angular_velocity.cross(&arm);
    body.angular_velocity = st.angular_velocity;
    let id = mb.add_body(body)?;
    let ws = 2.0 * std::f64::consts::PI * STIFF_FREQUENCY;
    let k = axis.index();
    let mut stiffness = [mode.mass * ws * ws; 3];
    let mut damping = [2.0 * STIFF_DAMPING_RATIO * mode.mass * ws; 3];
    stiffness[k] = mode.mass * mode.omega * mode.omega;
    damping[k] = 2.0 * mode.damping_ratio * mode.mass * mode.omega;
    let mut preload = st.rotation.transpose() * (-mode.mass * mb.gravity);
    preload[k] = 0.0;
    mb.add_force(Box::new(Bushing {
        name: format!("{name}/spring"),
        bodies: [Some(tank), Some(id)],
        points: [at, Vector3::zeros()],
        frame_i: Matrix3::identity(),
        frame_j: Matrix3::identity(),
        offset: Vector3::zeros(),
        stiffness,
        damping,
        preload,
        rotational_stiffness: [inertia * ws * ws; 3],
        rotational_damping: [2.0 * STIFF_DAMPING_RATIO * inertia * ws; 3],
        free_axis: None,
        matrix_stiffness: None,
        matrix_damping: None,
    }))?;
    Ok(id)
}

/// A train whose tanks carry equivalent slosh models.
#[derive(Debug)]
pub struct EquivalentTrain {
    /// The multibody system (cars, couplers, slosh bodies).
    pub mb: Multibody,
    /// The cars.
    pub cars: Vec<CarBodies>,
    /// Coupler force elements.
    pub couplers: Vec<usize>,
    /// Slosh bodies per car, one per mode.
    pub slosh: Vec<Vec<BodyId>>,
    /// The model of each car's liquid.
    pub model: EquivalentModel,
    /// Height of the tank body's centre of mass above the tank axis (the lading shift), m.
    pub tank_origin_height: f64,
}

impl EquivalentTrain {
    /// Slosh-body positions of car `k` in its tank frame (origin at the tank centre) at `q`.
    pub fn slosh_positions(&self, k: usize, q: &[f64]) -> Vec<[f64; 3]> {
        slosh_positions(&self.mb, self.cars[k].tank, &self.slosh[k], self.tank_origin_height, q)
    }
}

/// Positions of `bodies` in the tank frame of `tank` (whose centre of mass lies `shift` above
/// the tank centre) at `q`.
fn slosh_positions(mb: &Multibody, tank: BodyId, bodies: &[BodyId], shift: f64, q: &[f64]) -> Vec<[f64; 3]> {
    let v = vec![0.0; q.len()];
    let st = mb.state(Some(tank), q, &v);
    let origin = st.position - st.rotation * Vector3::new(0.0, 0.0, shift);
    bodies.iter().map(|b| (st.rotation.transpose() * (mb.state(Some(*b), q, &v).position - origin)).into()).collect()
}

/// Builds the train of `sc` with the liquid `cargo` in every tank (module docs).
pub fn build_equivalent_train(sc: &TrainScenario, cargo: &EquivalentCargo) -> Result<EquivalentTrain, AncfError> {
    let g = crate::track::GRAVITY;
    let model = cargo.model(&sc.car, g)?;
    let mut sc2 = sc.clone();
    let (ml, hl) = model.lading(sc.car.lading);
    sc2.car.lading = Some((ml, hl));
    // the car's own lading keeps its spread (its rod inertia); the fixed masses add theirs
    // below, per compartment
    let own = sc.car.lading.map_or(0.0, |l| l.0) * sc.car.lading_length * sc.car.lading_length / 12.0;
    sc2.car.lading_length = 0.0;
    sc2.car.tank.inertia[1] += own;
    sc2.car.tank.inertia[2] += own;
    sc2.car.carried_mass += model.sloshing_mass();
    for (m, c) in model.modes.iter().zip(&model.compartments) {
        let pitch = m.fixed_mass * (m.fixed_position[0].powi(2) + c.length * c.length / 12.0);
        sc2.car.tank.inertia[1] += pitch;
        sc2.car.tank.inertia[2] += pitch;
    }
    let (mut mb, cars, couplers) = build_train(&sc2)?;
    let shift = ml * hl / (sc2.car.tank.mass + ml);
    let mut slosh = Vec::with_capacity(cars.len());
    for car in &cars {
        let mut ids = Vec::with_capacity(model.modes.len());
        for (i, m) in model.modes.iter().enumerate() {
            let at = Vector3::from(m.position) - Vector3::new(0.0, 0.0, shift);
            ids.push(add_slosh_body(&mut mb, &format!("{}/slosh{}", car.name, i + 1), car.tank, at, m, model.axis)?);
        }
        slosh.push(ids);
    }
    Ok(EquivalentTrain { mb, cars, couplers, slosh, model, tank_origin_height: shift })
}

/// Results of a train run with equivalent slosh models.
#[derive(Debug, Clone, Default)]
pub struct EquivalentTrainRecord {
    /// The vehicle results (wheel loads, couplers, tanks).
    pub train: TrainRecord,
    /// Liquid centre of mass in the tank frame, m: `[sample][car]` (as
    /// [`super::FluidTrainRecord::oil_com_tank`]).
    pub oil_com_tank: Vec<Vec<[f64; 3]>>,
    /// Displacement of each slosh mass from its rest position along the slosh axis, m:
    /// `[sample][car][mode]`.
    pub slosh_displacement: Vec<Vec<Vec<f64>>>,
    /// The model of each car's liquid (`None` before a run is built).
    pub model: Option<EquivalentModel>,
}

impl EquivalentTrainRecord {
    /// Column names of [`Self::row`]: the [`TrainRecord::columns`] followed, per car, by the
    /// liquid centre of mass (tank frame), then the slosh displacements numbered car by car
    /// (`slosh_displacement[car · modes + mode]`).
    pub fn columns(wheelsets: usize, couplers: usize, cars: usize, modes: usize) -> Vec<String> {
        let mut c = TrainRecord::columns(wheelsets, couplers, cars);
        for k in 0..cars {
            c.extend(["x", "y", "z"].map(|a| format!("oil_com_tank[{k}].{a}")));
        }
        c.extend((0..cars * modes).map(|j| format!("slosh_displacement[{j}]")));
        c
    }

    /// Sample `i` as one flat row in the order of [`Self::columns`].
    pub fn row(&self, i: usize) -> Vec<f64> {
        let mut r = self.train.row(i);
        for c in &self.oil_com_tank[i] {
            r.extend(c);
        }
        for d in &self.slosh_displacement[i] {
            r.extend(d);
        }
        r
    }
}

/// An equivalent-model run that stopped early: why, and what was recorded.
pub type EquivalentTrainFailure = RunFailure<EquivalentTrainRecord>;

fn record_equivalent(
    mb: &Multibody,
    (cars, slosh, model, shift): (&[CarBodies], &[Vec<BodyId>], &EquivalentModel, f64),
    q: &[f64],
    rec: &mut EquivalentTrainRecord,
) {
    let k_axis = model.axis.index();
    let mut com = Vec::with_capacity(cars.len());
    let mut disp = Vec::with_capacity(cars.len());
    for (car, ids) in cars.iter().zip(slosh) {
        let pos = slosh_positions(mb, car.tank, ids, shift, q);
        com.push(model.center_of_mass(&pos));
        disp.push(model.modes.iter().zip(&pos).map(|(m, p)| p[k_axis] - m.position[k_axis]).collect());
    }
    rec.oil_com_tank.push(com);
    rec.slosh_displacement.push(disp);
}

/// [`run_vehicle`](super::run_vehicle) of an equivalent-model cargo, without observer or stream.
pub fn run_equivalent_train(sc: &TrainScenario, cargo: &EquivalentCargo) -> RunResult<EquivalentTrainRecord> {
    super::run_vehicle(sc, cargo, &mut |_| true, None)
}

impl Cargo for EquivalentCargo {
    type Record = EquivalentTrainRecord;
    fn columns(&self, sc: &TrainScenario) -> Result<Vec<String>, AncfError> {
        let modes = self.model(&sc.car, crate::track::GRAVITY)?.modes.len();
        Ok(EquivalentTrainRecord::columns(4 * sc.cars, sc.cars.saturating_sub(1), sc.cars, modes))
    }
    fn run(
        &self,
        sc: &TrainScenario,
        observe: Observer<'_>,
        sink: Option<SampleSink<'_>>,
    ) -> RunResult<EquivalentTrainRecord> {
        run_equivalent(sc, self, observe, sink)
    }
}

fn run_equivalent(
    sc: &TrainScenario,
    cargo: &EquivalentCargo,
    observe: Observer<'_>,
    sink: Option<SampleSink<'_>>,
) -> RunResult<EquivalentTrainRecord> {
    let built = build_equivalent_train(sc, cargo)?;
    let EquivalentTrain { mb, cars, couplers, slosh, model, tank_origin_height } = built;
    let rec = EquivalentTrainRecord {
        train: TrainRecord { static_wheel_load: cars[0].static_wheel_load, dof: mb.dof(), ..Default::default() },
        model: Some(model.clone()),
        ..Default::default()
    };
    let init = mb.initial_coordinates();
    let hints = cars.iter().flat_map(|c| [c.station; 4]).collect();
    let run = EquivalentRun { sc, cars, couplers, slosh, model, tank_origin_height, hints };
    Ok(drive(run, mb, init, sc, observe, sink, rec))
}

/// The equivalent-model run ([`run_equivalent_train`]): the vehicle channels and the slosh
/// masses' (the load filter needs the vehicle's only).
struct EquivalentRun<'a> {
    sc: &'a TrainScenario,
    cars: Vec<CarBodies>,
    couplers: Vec<usize>,
    slosh: Vec<Vec<BodyId>>,
    model: EquivalentModel,
    tank_origin_height: f64,
    /// Warm starts of the wheel/rail search at the recorded samples.
    hints: Vec<f64>,
}

impl TrainRun for EquivalentRun<'_> {
    type System = Multibody;
    type Record = EquivalentTrainRecord;
    fn train(rec: &mut EquivalentTrainRecord) -> &mut TrainRecord {
        &mut rec.train
    }
    fn sample(
        &mut self,
        hht: &mut Hht<Multibody>,
        _k: usize,
        rec: &mut EquivalentTrainRecord,
        full: bool,
    ) -> Result<(), IntegratorError> {
        let (t, q, v, a) = (hht.t(), hht.q().to_vec(), hht.v().to_vec(), hht.a().to_vec());
        let mb = hht.system_observed();
        record_sample(
            mb,
            (t, &q, &v, &a),
            &self.sc.track,
            &self.cars,
            &self.couplers,
            &mut self.hints,
            &mut rec.train,
        )?;
        if full {
            let parts = (self.cars.as_slice(), self.slosh.as_slice(), &self.model, self.tank_origin_height);
            record_equivalent(hht.system(), parts, &q, rec);
        }
        Ok(())
    }
    fn clear_samples(rec: &mut EquivalentTrainRecord) {
        rec.train.clear_samples();
    }
    fn loads_into(rec: &EquivalentTrainRecord, i: usize, out: &mut Vec<f64>) {
        rec.train.loads_into(i, out);
    }
    fn set_loads(rec: &mut EquivalentTrainRecord, i: usize, loads: &[f64]) {
        rec.train.set_loads(i, loads);
    }
    fn row(rec: &EquivalentTrainRecord, i: usize) -> Vec<f64> {
        rec.row(i)
    }
    fn hints(&mut self) -> &mut Vec<f64> {
        &mut self.hints
    }
}
