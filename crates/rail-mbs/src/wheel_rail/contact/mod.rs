//! Contact-point search (ECF-A), normal and tangential contact forces.

use std::sync::Arc;

use nalgebra::{Matrix3, Matrix4, Vector3, Vector4};

use super::ContactError;
use super::creep::{CreepForces, CreepModel, Creepages, creep_forces};
use super::hertz::{HertzConstants, Material, combined_modulus};
use super::kik_piotrowski::{KpPatch, PatchModel, PatchSummary, SampledSeparation};
use crate::profile::Profile;
use crate::track::{Side, Track};

mod combination;
pub use combination::{InterpenetrationRegion, PATCH_DISTANCE_RANGE, PatchCombination};

/// Wheel geometry: profile, nominal radius and placement on the wheelset body.
#[derive(Debug, Clone)]
pub struct WheelGeometry {
    /// Wheel profile (crate convention: `y` to the field side, `z` up, local radius
    /// `r0 − z`).
    pub profile: Profile,
    /// Nominal rolling radius `r0` at the profile origin, m.
    pub nominal_radius: f64,
    /// Lateral distance from the body origin (wheelset centre) to the wheel profile
    /// origin, m (positive; e.g. 0.75 m for S1002 with 1360 mm back-to-back).
    pub profile_offset: f64,
    /// Which wheel of the wheelset.
    pub side: Side,
}

impl WheelGeometry {
    /// Surface point and derivatives in the body frame at `(u, θ)`:
    /// `[w, w_u, w_θ, w_uu, w_uθ, w_θθ]`.
    fn surface(&self, u: f64, th: f64) -> [Vector3<f64>; 6] {
        let sg = self.side.sign();
        let (z, dz, ddz) = self.profile.eval(u);
        let rho = self.nominal_radius - z;
        let (rp, rpp) = (-dz, -ddz);
        let (s, c) = th.sin_cos();
        [
            Vector3::new(rho * s, sg * (self.profile_offset + u), -rho * c),
            Vector3::new(rp * s, sg, -rp * c),
            Vector3::new(rho * c, 0.0, rho * s),
            Vector3::new(rpp * s, 0.0, -rpp * c),
            Vector3::new(rp * c, 0.0, rp * s),
            Vector3::new(-rho * s, 0.0, rho * c),
        ]
    }
}

/// Where the rail runs.
#[derive(Debug, Clone)]
pub enum RailPath {
    /// Straight rail along global `+X` (track frame = global frame, `s = X`), with a
    /// fixed inward cant (rad).
    Straight {
        /// Inward cant of the rail, rad (e.g. `1/40`); zero for pre-canted profiles.
        inward_cant: f64,
    },
    /// Rail following a [`Track`] (centreline frame, super-elevation, rail cant).
    Track(Arc<Track>),
}

/// Rail geometry: profile, side and placement relative to the track centreline.
#[derive(Debug, Clone)]
pub struct RailGeometry {
    /// Rail profile (crate convention: `y` to the field side, `z` up).
    pub profile: Profile,
    /// Which rail.
    pub side: Side,
    /// Lateral distance from the track centreline to the rail profile origin, m
    /// (positive). See [`RailGeometry::offset_for_gauge`].
    pub profile_offset: f64,
    /// Height of the rail profile origin above the track centreline, m.
    pub vertical_offset: f64,
    /// Rail path.
    pub path: RailPath,
}

impl RailGeometry {
    /// Lateral offset of the profile origin such that the gauge point — the gauge-side
    /// point `gauge_depth` below the highest point of `profile` — lies at `gauge/2` from
    /// the centreline. Returns `None` when the profile does not reach that depth.
    pub fn offset_for_gauge(profile: &Profile, gauge: f64, gauge_depth: f64) -> Option<f64> {
        let (y_top, z_top) = profile.highest_point();
        let yg = profile.crossing(y_top, -1.0, z_top - gauge_depth)?;
        Some(0.5 * gauge - yg)
    }

    /// Frame (origin, rotation) of the rail profile at `s` and its first and second
    /// derivatives with respect to `s`.
    fn frame_derivs(&self, s: f64) -> RailFrameDerivs {
        let sg = self.side.sign();
        match &self.path {
            RailPath::Straight { inward_cant } => {
                let ang = sg * inward_cant;
                RailFrameDerivs {
                    origin: Vector3::new(s, sg * self.profile_offset, self.vertical_offset),
                    rot: rot_x(ang),
                    d_origin: Vector3::new(1.0, 0.0, 0.0),
                    d_rot: Matrix3::zeros(),
                    dd_origin: Vector3::zeros(),
                    dd_rot: Matrix3::zeros(),
                }
            }
            RailPath::Track(track) => {
                let f = |s: f64| -> (Vector3<f64>, Matrix3<f64>) {
                    let fr = track.frame(s);
                    // the rail's irregularity translates its profile (track frame)
                    let (dy, dz) = track.rail_offset(s, self.side);
                    let o = fr.origin
                        + fr.rotation * Vector3::new(0.0, sg * self.profile_offset + dy, self.vertical_offset + dz);
                    let r = fr.rotation * rot_x(sg * track.rail_inward_cant(s, self.side));
                    (o, r)
                };
                let h = 0.02;
                let (o0, r0) = f(s);
                let (op, rp) = f(s + h);
                let (om, rm) = f(s - h);
                RailFrameDerivs {
                    origin: o0,
                    rot: r0,
                    d_origin: (op - om) / (2.0 * h),
                    d_rot: (rp - rm) / (2.0 * h),
                    dd_origin: (op - 2.0 * o0 + om) / (h * h),
                    dd_rot: (rp - 2.0 * r0 + rm) / (h * h),
                }
            }
        }
    }

    /// Rail surface point and derivatives at `(s, v)`: `[r, r_s, r_v, r_ss, r_sv, r_vv]`.
    fn surface(&self, s: f64, v: f64) -> [Vector3<f64>; 6] {
        let sg = self.side.sign();
        let fd = self.frame_derivs(s);
        let (z, dz, ddz) = self.profile.eval(v);
        let p = Vector3::new(0.0, sg * v, z);
        let pv = Vector3::new(0.0, sg, dz);
        let pvv = Vector3::new(0.0, 0.0, ddz);
        [
            fd.origin + fd.rot * p,
            fd.d_origin + fd.d_rot * p,
            fd.rot * pv,
            fd.dd_origin + fd.dd_rot * p,
            fd.d_rot * pv,
            fd.rot * pvv,
        ]
    }

    /// Arc length on the rail path closest to a point (the wheel centre).
    fn station(&self, p: &Vector3<f64>, hint: Option<f64>) -> Result<f64, ContactError> {
        match &self.path {
            RailPath::Straight { .. } => Ok(p.x),
            RailPath::Track(t) => Ok(t.project(p, hint)?.s),
        }
    }
}

struct RailFrameDerivs {
    origin: Vector3<f64>,
    rot: Matrix3<f64>,
    d_origin: Vector3<f64>,
    d_rot: Matrix3<f64>,
    dd_origin: Vector3<f64>,
    dd_rot: Matrix3<f64>,
}

fn rot_x(a: f64) -> Matrix3<f64> {
    let (s, c) = a.sin_cos();
    Matrix3::new(1.0, 0.0, 0.0, 0.0, c, -s, 0.0, s, c)
}

/// Pose and velocity of the wheel(set) body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelPose {
    /// Body origin (wheelset centre on the axle axis), m (global).
    pub position: Vector3<f64>,
    /// Rotation body → global. The spin about the axle may be included or not (the wheel
    /// is a surface of revolution).
    pub rotation: Matrix3<f64>,
    /// Velocity of the body origin, m/s (global).
    pub velocity: Vector3<f64>,
    /// Angular velocity, rad/s (global), including the spin about the axle.
    pub angular_velocity: Vector3<f64>,
}

impl WheelPose {
    /// A pose at rest.
    pub fn at_rest(position: Vector3<f64>, rotation: Matrix3<f64>) -> Self {
        Self { position, rotation, velocity: Vector3::zeros(), angular_velocity: Vector3::zeros() }
    }

    /// The mirror image of this pose in the track's vertical centre plane (global `y → −y`):
    /// the pose of the other side's wheel, with the same (symmetric) profiles, that is the
    /// mirror image of this one (a right wheel at shift `y`, yaw `ψ`, roll `φ` mirrors a left
    /// wheel at `−y`, `−ψ`, `−φ`). With the reflection `M = diag(1, −1, 1)`, positions and
    /// velocities map as `x → M x` ([`mirror_vector`]), rotations as `R → M R M`, and the
    /// angular velocity, a pseudovector, as `ω → −M ω` ([`mirror_pseudovector`]). Forces of
    /// the mirrored contact are then `M F`, moments `−M m`.
    pub fn mirrored(&self) -> Self {
        let m = Matrix3::from_diagonal(&Vector3::new(1.0, -1.0, 1.0));
        Self {
            position: mirror_vector(&self.position),
            rotation: m * self.rotation * m,
            velocity: mirror_vector(&self.velocity),
            angular_velocity: mirror_pseudovector(&self.angular_velocity),
        }
    }
}

/// A (polar) vector — position, velocity, force — reflected in the track's vertical centre
/// plane: `M v` with `M = diag(1, −1, 1)` ([`WheelPose::mirrored`]).
pub fn mirror_vector(v: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(v.x, -v.y, v.z)
}

/// A pseudovector — angular velocity, moment — reflected in the track's vertical centre
/// plane: `−M m` with `M = diag(1, −1, 1)` ([`WheelPose::mirrored`]).
pub fn mirror_pseudovector(m: &Vector3<f64>) -> Vector3<f64> {
    Vector3::new(-m.x, m.y, -m.z)
}

/// Settings of the contact search and force evaluation.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactSettings {
    /// Number of lateral samples of the scan over the wheel profile.
    pub scan_points: usize,
    /// Seeds from scan minima whose gap (the scan's, along the rail normal) exceeds this are
    /// ignored, m.
    pub scan_gap_limit: f64,
    /// Newton tolerance on the parameter update, m (and rad).
    pub newton_tolerance: f64,
    /// Maximum Newton iterations.
    pub max_iterations: usize,
    /// Two solutions closer than this in both lateral parameters (rail `v`, wheel `u`) are
    /// merged (the deeper one kept), m. This removes duplicates of one contact point (two scan
    /// seeds converging to the same minimum of the gap); it is not a patch rule. Two distinct
    /// minima of the gap stay two points however close their patches lie (unless
    /// [`Self::patch_combination`] combines them), where
    /// CONTACT (A_SEP, D_SEP, D_COMB; the Manchester benchmark input: 90°, 8 mm, 4 mm)
    /// combines interpenetration regions whose facing ends lie within D_SEP into one patch
    /// (docs/validation.md, "One patch or two: our rule and CONTACT's").
    pub merge_distance: f64,
    /// Scan every call (true, robust) or only when a warm start fails (false).
    pub always_scan: bool,
    /// Lower bound of the speed used to normalise creepages, m/s.
    pub min_speed: f64,
    /// Floor for the relative curvatures `A`, `B` (1/m) used by the Hertz solution.
    /// Near-conformal points (e.g. a worn or S1002 throat against a rail corner) can
    /// have a vanishing or negative relative curvature, for which Hertz theory has no
    /// solution; they are evaluated with this floor instead (a documented
    /// approximation — a non-Hertzian model would be needed there).
    pub min_relative_curvature: f64,
    /// How neighbouring contact points form patches: [`PatchCombination::Separate`] (one patch
    /// per point, the default) or CONTACT's D_SEP/D_COMB rule ([`PatchCombination::Contact`]).
    pub patch_combination: PatchCombination,
}

impl Default for ContactSettings {
    fn default() -> Self {
        Self {
            scan_points: 400,
            scan_gap_limit: 2e-3,
            newton_tolerance: 1e-11,
            max_iterations: 40,
            merge_distance: 1e-3,
            always_scan: true,
            min_speed: 0.05,
            min_relative_curvature: 0.1,
            patch_combination: PatchCombination::Separate,
        }
    }
}

/// How a contact point was obtained.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum ContactMethod {
    /// Newton–Raphson on `C(q) = 0` converged.
    Newton,
    /// Newton failed; the point is the refined minimum of the scan's gap.
    ScanFallback,
}

/// Geometric solution of one potential contact.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactGeometry {
    /// Surface parameters `[s1r, s2r, s1w, s2w]` = `[s, v, u, θ]`.
    pub params: [f64; 4],
    /// Contact point on the rail, m (global).
    pub point_rail: Vector3<f64>,
    /// Contact point on the wheel, m (global).
    pub point_wheel: Vector3<f64>,
    /// Unit normal, out of the rail into the wheel.
    pub normal: Vector3<f64>,
    /// Rolling direction `e1` (unit, in the tangent plane, along the direction of
    /// travel; `+x` of the body when at rest).
    pub e1: Vector3<f64>,
    /// `e2 = n × e1`.
    pub e2: Vector3<f64>,
    /// Penetration `δ = −r_wr·n̂`, m (positive = overlap).
    pub penetration: f64,
    /// Relative curvature `A` along `e1`, 1/m (`h = A x² + B y²`).
    pub curvature_x: f64,
    /// Relative curvature `B` along `e2`, 1/m.
    pub curvature_y: f64,
    /// How it was found.
    pub method: ContactMethod,
}

/// A loaded contact point with forces.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct ContactPoint {
    /// Geometry.
    pub geometry: ContactGeometry,
    /// Hertz constants (stiffness and ellipse scaling) at the contact point's curvatures (the
    /// normal force's law for [`PatchModel::Hertz`] only).
    pub hertz: HertzConstants,
    /// Semi-axes `(a, b)` along `e1`, `e2`, m: Hertz's ellipse, or the equivalent ellipse of a
    /// Kik–Piotrowski patch (its area and length-to-width ratio).
    pub semi_axes: (f64, f64),
    /// Penetration rate `δ̇`, m/s.
    pub penetration_rate: f64,
    /// Normal force (≥ 0), N, acting on the wheel along `+n`.
    pub normal_force: f64,
    /// Creepages.
    pub creepages: Creepages,
    /// Creep forces on the wheel (along `e1`, `e2`, about `n`).
    pub creep: CreepForces,
    /// The non-elliptic patch of [`PatchModel::KikPiotrowski`] (`None` for Hertz, whose
    /// patch is the ellipse of `semi_axes`).
    pub patch: Option<PatchSummary>,
}

impl ContactPoint {
    /// Total contact force on the wheel, N (global). The rail receives the opposite.
    pub fn force_on_wheel(&self) -> Vector3<f64> {
        let g = &self.geometry;
        g.normal * self.normal_force + g.e1 * self.creep.longitudinal + g.e2 * self.creep.lateral
    }
    /// Moment on the wheel about point `about` (e.g. the wheelset centre), N·m. The creep
    /// forces and spin moment act at the contact point; a Kik–Piotrowski patch's normal
    /// force acts at its pressure centroid ([`Self::reference_point`]).
    pub fn moment_on_wheel(&self, about: &Vector3<f64>) -> Vector3<f64> {
        let g = &self.geometry;
        let p = 0.5 * (g.point_rail + g.point_wheel);
        let m = (p - about).cross(&self.force_on_wheel()) + g.normal * self.creep.spin_moment;
        match &self.patch {
            None => m,
            Some(s) => m + (g.e2 * s.centroid).cross(&(g.normal * self.normal_force)),
        }
    }
    /// Contact reference point, m: the pressure centroid of a Kik–Piotrowski patch, the
    /// contact point ([`Self::point`]) for Hertz.
    pub fn reference_point(&self) -> Vector3<f64> {
        match &self.patch {
            None => self.point(),
            Some(s) => self.point() + self.geometry.e2 * s.centroid,
        }
    }
    /// The same patch carrying `k` times its normal and creep forces and spin moment (a share
    /// of a blend, [`PatchCombination::Contact`] between `d_comb` and `d_sep`).
    pub fn scaled(&self, k: f64) -> Self {
        let mut p = *self;
        p.normal_force *= k;
        p.creep.longitudinal *= k;
        p.creep.lateral *= k;
        p.creep.spin_moment *= k;
        p
    }
    /// Contact point (midway between the surface points), m.
    pub fn point(&self) -> Vector3<f64> {
        0.5 * (self.geometry.point_rail + self.geometry.point_wheel)
    }
}

/// One wheel against one rail: geometry, materials, laws and the warm-start state.
#[derive(Debug, Clone)]
pub struct WheelRailContact {
    /// Wheel.
    pub wheel: WheelGeometry,
    /// Rail.
    pub rail: RailGeometry,
    /// Wheel material.
    pub wheel_material: Material,
    /// Rail material.
    pub rail_material: Material,
    /// Friction coefficient.
    pub friction: f64,
    /// Friction over the rail profile and along the track; when set it replaces `friction`
    /// at every contact point, each point taking the μ of its own location.
    pub friction_map: Option<std::sync::Arc<super::FrictionMap>>,
    /// Creep law.
    pub creep_model: CreepModel,
    /// Normal-contact patch model (Hertz by default; [`PatchModel::KikPiotrowski`] for the
    /// non-elliptic patch of the gauge corner and flange).
    pub patch_model: PatchModel,
    /// Hunt–Crossley damping coefficient `d` in `f_n = K_h δ^{3/2}(1 + d δ̇)`, s/m.
    pub damping: f64,
    /// Search settings.
    pub settings: ContactSettings,
    previous: Vec<[f64; 4]>,
    /// Whether every point of `previous` is a converged, convex Newton solution (none a scan
    /// fall-back): only then can [`Self::evaluate_perturbed`] start from them alone.
    previous_exact: bool,
    last_station: Option<f64>,
    /// Reusable buffers of the search (no allocation per call once sized).
    scratch: SearchScratch,
}

/// Buffers of [`WheelRailContact`]'s contact search, reused between calls.
#[derive(Debug, Clone, Default)]
struct SearchScratch {
    /// Scan gap and parameters at each scan point.
    scan: Vec<(f64, [f64; 4])>,
    /// Scan seeds `(gap, q, u_lo, u_hi)`.
    seeds: Vec<(f64, [f64; 4], f64, f64)>,
    /// Geometry of the latest search.
    geometry: Vec<ContactGeometry>,
    /// Loaded points of the latest [`WheelRailContact::evaluate_cached`].
    points: Vec<ContactPoint>,
    /// The warm start kept across an observation or a Jacobian column
    /// (`WheelRailContact::keeping_warm_start`).
    saved_previous: Vec<[f64; 4]>,
}

impl WheelRailContact {
    /// New contact pair with steel on both sides, μ = 0.3, Shen–Hedrick–Elkins creep, no
    /// damping and default settings.
    pub fn new(wheel: WheelGeometry, rail: RailGeometry) -> Self {
        Self {
            wheel,
            rail,
            wheel_material: Material::steel(),
            rail_material: Material::steel(),
            friction: 0.3,
            friction_map: None,
            creep_model: CreepModel::ShenHedrickElkins,
            patch_model: PatchModel::Hertz,
            damping: 0.0,
            settings: ContactSettings::default(),
            previous: Vec::new(),
            previous_exact: false,
            last_station: None,
            scratch: SearchScratch::default(),
        }
    }

    /// Forgets the warm-start state.
    pub fn reset(&mut self) {
        self.previous.clear();
        self.previous_exact = false;
        self.last_station = None;
    }

    /// Appends the search's warm start (its points, whether they are exact, the station) to
    /// `out`, as [`Self::restore_warm_start`] reads it back: a resumed run then searches from
    /// where the interrupted one would have.
    pub fn save_warm_start(&self, out: &mut Vec<f64>) {
        out.push(self.previous.len() as f64);
        out.extend(self.previous.iter().flatten());
        out.push(if self.previous_exact { 1.0 } else { 0.0 });
        out.push(self.last_station.map_or(0.0, |_| 1.0));
        out.push(self.last_station.unwrap_or(0.0));
    }

    /// Reads a warm start written by [`Self::save_warm_start`] from the front of `data`,
    /// advancing it; `None` when `data` is too short or malformed.
    pub fn restore_warm_start(&mut self, data: &mut &[f64]) -> Option<()> {
        let n = *data.first()?;
        if !(n >= 0.0 && n.fract() == 0.0) {
            return None;
        }
        let n = n as usize;
        let rest = data.get(1..)?;
        let (points, rest) = (rest.get(..4 * n)?, rest.get(4 * n..)?);
        let [exact, has_station, station] = *rest.get(..3)? else { return None };
        self.previous.clear();
        self.previous.extend(points.chunks_exact(4).map(|c| [c[0], c[1], c[2], c[3]]));
        self.previous_exact = exact == 1.0;
        self.last_station = (has_station == 1.0).then_some(station);
        *data = &rest[3..];
        Some(())
    }

    /// Previous solutions used for warm starts.
    pub fn previous_solutions(&self) -> &[[f64; 4]] {
        &self.previous
    }

    fn wheel_global(&self, pose: &WheelPose, u: f64, th: f64) -> [Vector3<f64>; 6] {
        let w = self.wheel.surface(u, th);
        let a = &pose.rotation;
        [pose.position + a * w[0], a * w[1], a * w[2], a * w[3], a * w[4], a * w[5]]
    }

    /// Contact conditions `C(q)` of seed 000 §7.2 for `q = [s, v, u, θ]` (rail normal
    /// oriented out of the rail).
    pub fn constraint(&self, pose: &WheelPose, q: &[f64; 4]) -> Vector4<f64> {
        let r = self.rail.surface(q[0], q[1]);
        let w = self.wheel_global(pose, q[2], q[3]);
        let d = w[0] - r[0];
        let n = r[1].cross(&r[2]) * self.rail.side.sign();
        Vector4::new(d.dot(&r[1]), d.dot(&r[2]), n.dot(&w[1]), n.dot(&w[2]))
    }

    /// Analytic Jacobian `∂C/∂q`.
    pub fn constraint_jacobian(&self, pose: &WheelPose, q: &[f64; 4]) -> Matrix4<f64> {
        let sg = self.rail.side.sign();
        let [rr, rs, rv, rss, rsv, rvv] = self.rail.surface(q[0], q[1]);
        let [rw, wu, wt, wuu, wut, wtt] = self.wheel_global(pose, q[2], q[3]);
        let d = rw - rr;
        let n = rs.cross(&rv) * sg;
        let dn_ds = (rss.cross(&rv) + rs.cross(&rsv)) * sg;
        let dn_dv = (rsv.cross(&rv) + rs.cross(&rvv)) * sg;
        Matrix4::new(
            -rs.dot(&rs) + d.dot(&rss),
            -rv.dot(&rs) + d.dot(&rsv),
            wu.dot(&rs),
            wt.dot(&rs),
            -rs.dot(&rv) + d.dot(&rsv),
            -rv.dot(&rv) + d.dot(&rvv),
            wu.dot(&rv),
            wt.dot(&rv),
            dn_ds.dot(&wu),
            dn_dv.dot(&wu),
            n.dot(&wuu),
            n.dot(&wut),
            dn_ds.dot(&wt),
            dn_dv.dot(&wt),
            n.dot(&wut),
            n.dot(&wtt),
        )
    }

    /// Newton–Raphson from `q0`; returns the converged parameters.
    pub fn newton(&self, pose: &WheelPose, q0: [f64; 4]) -> Result<[f64; 4], ContactError> {
        self.newton_within(pose, q0, self.settings.max_iterations)
    }

    /// [`Self::newton`] with at most `max_iterations` iterations.
    fn newton_within(&self, pose: &WheelPose, q0: [f64; 4], max_iterations: usize) -> Result<[f64; 4], ContactError> {
        let mut q = q0;
        let mut res = f64::INFINITY;
        for it in 0..max_iterations {
            let c = self.constraint(pose, &q);
            res = c.norm();
            if !res.is_finite() {
                return Err(ContactError::NoConvergence { iterations: it, residual: res });
            }
            let j = self.constraint_jacobian(pose, &q);
            let dq = j.lu().solve(&(-c)).ok_or(ContactError::SingularJacobian)?;
            // Damp large steps (profiles are only locally well approximated).
            let lim = [0.05, 4e-3, 4e-3, 0.05];
            let mut scale = 1.0f64;
            for k in 0..4 {
                if dq[k].abs() > lim[k] {
                    scale = scale.min(lim[k] / dq[k].abs());
                }
            }
            if dq.amax() < self.settings.newton_tolerance {
                for k in 0..4 {
                    q[k] += dq[k];
                }
                return Ok(q);
            }
            // Backtracking on |C| (the Newton direction is a descent direction for |C|²);
            // this breaks the 2-cycles seen on strongly curved profile regions.
            let mut alpha = scale;
            let mut accepted = false;
            for _ in 0..12 {
                let mut trial = q;
                for k in 0..4 {
                    trial[k] += alpha * dq[k];
                }
                if self.constraint(pose, &trial).norm() < res {
                    q = trial;
                    accepted = true;
                    break;
                }
                alpha *= 0.5;
            }
            if !accepted {
                for k in 0..4 {
                    q[k] += alpha * dq[k];
                }
            }
        }
        Err(ContactError::NoConvergence { iterations: max_iterations, residual: res })
    }

    /// Geometry (points, normal, penetration, curvatures) at parameters `q`.
    pub fn geometry_at(&self, pose: &WheelPose, q: [f64; 4], method: ContactMethod) -> ContactGeometry {
        let sg = self.rail.side.sign();
        let [rr, rs, rv, rss, rsv, rvv] = self.rail.surface(q[0], q[1]);
        let [rw, wu, wt, wuu, wut, wtt] = self.wheel_global(pose, q[2], q[3]);
        let n = (rs.cross(&rv) * sg).normalize();
        let pen = -(rw - rr).dot(&n);
        // Rolling direction: wheel circumferential tangent projected on the tangent plane,
        // oriented with the direction of travel (body +x when at rest or moving forward).
        let mut e1 = wt - n * wt.dot(&n);
        let travel = if pose.velocity.norm() > 1e-9 { pose.velocity } else { pose.rotation.column(0).into() };
        if e1.dot(&travel) < 0.0 {
            e1 = -e1;
        }
        let e1 = e1.normalize();
        let e2 = n.cross(&e1);
        // Convex curvature tensors in the (e1, e2) basis; rail outward normal = n,
        // wheel outward normal = −n.
        let kr = curvature_tensor(&rs, &rv, &rss, &rsv, &rvv, &n, &e1, &e2, -1.0);
        let kw = curvature_tensor(&wu, &wt, &wuu, &wut, &wtt, &n, &e1, &e2, 1.0);
        let k = kr + kw;
        // Principal values; assign the one whose direction is closer to e1 to x.
        let (k11, k12, k22) = (k[(0, 0)], k[(0, 1)], k[(1, 1)]);
        let mean = 0.5 * (k11 + k22);
        let rad = (0.25 * (k11 - k22).powi(2) + k12 * k12).sqrt();
        let (kx, ky) = if k11 <= k22 { (mean - rad, mean + rad) } else { (mean + rad, mean - rad) };
        ContactGeometry {
            params: q,
            point_rail: rr,
            point_wheel: rw,
            normal: n,
            e1,
            e2,
            penetration: pen,
            curvature_x: 0.5 * kx,
            curvature_y: 0.5 * ky,
            method,
        }
    }

    /// Gap of the scan at lateral wheel coordinate `u`, with the station frame; returns
    /// `(gap, [s, v, u, θ])`, `gap = +∞` when the wheel's point is not above the rail
    /// profile. The gap is the signed distance, in the rail's cross-section, from the
    /// wheel's lowest point at `u` to the rail profile: along the rail normal at the foot
    /// `v` of the perpendicular (positive outside the rail), which the contact conditions
    /// make stationary. The vertical gap to the rail point below overstates gaps and
    /// interpenetrations on a steep flange by 1/cos of the slope (about 3 at 70°), so that
    /// its minima can lie millimetres from the contact points: on S1002/UIC 60 at the flange
    /// root it had one minimum on the flange where the contact point lay 5.6 mm away on the
    /// root, and the search lost that point (docs/validation.md, "The scan's gap at the
    /// flange root"). The foot is found by at most `steps` Newton steps from the point below
    /// (the scan takes one, the refinement of a fall-back point four); a foot at an end of the
    /// rail profile (a cut, not a surface) gives `+∞`.
    fn scan_gap(&self, pose: &WheelPose, s0: f64, fd: &RailFrameDerivs, u: f64, steps: usize) -> (f64, [f64; 4]) {
        let sg = self.rail.side.sign();
        let (p, th) = self.wheel_section(pose, fd, u);
        let (py, pz) = (sg * p.y, p.z);
        let (lo, hi) = self.rail.profile.y_range();
        if py < lo || py > hi {
            return (f64::INFINITY, [s0, py, u, th]);
        }
        // The distance to the tangent line at the point below bounds the distance to the (convex)
        // rail head from below: a point farther than the seeds' gap limit cannot seed, and keeps
        // that bound, which still exceeds every gap that can seed, so that the scan's minima
        // below the limit are those of the distance.
        let mut v = py;
        let (mut z, mut dz, mut ddz) = self.rail.profile.eval(v);
        let bound = (pz - z) / (1.0 + dz * dz).sqrt();
        if bound > self.settings.scan_gap_limit {
            return (bound, [s0 + p.x, v, u, th]);
        }
        // foot of the perpendicular: Newton on d/dv |p − r(v)|²/2 from the point below,
        // each step limited to 2 mm
        for it in 0..steps {
            if it > 0 {
                (z, dz, ddz) = self.rail.profile.eval(v);
            }
            let (ey, ez) = (py - v, pz - z);
            let (f1, f2) = (-ey - ez * dz, 1.0 + dz * dz - ez * ddz);
            if f2 <= 0.0 {
                break;
            }
            let step = (-f1 / f2).clamp(-2e-3, 2e-3);
            v = (v + step).clamp(lo, hi);
            if step.abs() < 1e-8 {
                break;
            }
        }
        // a foot at an end of the rail profile (a cut, not a surface) is no contact
        if v <= lo || v >= hi {
            return (f64::INFINITY, [s0 + p.x, v, u, th]);
        }
        let (z, dz, _) = self.rail.profile.eval(v);
        ((pz - z - (py - v) * dz) / (1.0 + dz * dz).sqrt(), [s0 + p.x, v, u, th])
    }

    /// Lowest point of the wheel circle at lateral profile coordinate `u` in the rail frame
    /// `fd` (its coordinates `p` in that frame) and its angle `θ`.
    fn wheel_section(&self, pose: &WheelPose, fd: &RailFrameDerivs, u: f64) -> (Vector3<f64>, f64) {
        let mt = fd.rot.transpose();
        let w0 = self.wheel.surface(u, 0.0);
        let centre = pose.position + pose.rotation * Vector3::new(0.0, w0[0].y, 0.0);
        let (a, b) = Self::wheel_axes(pose, fd);
        let cl = mt * (centre - fd.origin);
        let th = Self::lowest_angle(&a, &b);
        let rho = self.wheel.nominal_radius - self.wheel.profile.z(u);
        (cl + (a * th.sin() - b * th.cos()) * rho, th)
    }

    /// The undeformed separation across contact `g` for the Kik–Piotrowski patch
    /// ([`super::kik_piotrowski`]): in the rail's cross-section at the contact point, the
    /// distance along the rail normal between the wheel (the lowest points of its circles)
    /// and the rail as a function of the lateral coordinate `y` along the contact plane
    /// (oriented with `e2`, 0 at the contact point, `h(0) = 0`), sampled every `spacing` m
    /// over `|y| ≤ half_width` (less where a profile ends), with the relative longitudinal
    /// curvature `A(y) = A(0) ρ(u_c)/ρ(u(y))` of the wheel's in-situ radius.
    pub fn separation(
        &self,
        pose: &WheelPose,
        g: &ContactGeometry,
        half_width: f64,
        spacing: f64,
    ) -> Result<SampledSeparation, ContactError> {
        let sg = self.rail.side.sign();
        let fd = self.rail.frame_derivs(g.params[0]);
        let (vc, uc) = (g.params[1], g.params[2]);
        let (zc, dzc, _) = self.rail.profile.eval(vc);
        let norm = (1.0 + dzc * dzc).sqrt();
        let (tv, tz) = (1.0 / norm, dzc / norm);
        // (τ, ζ): along the rail's tangent and normal at the contact point.
        let local = |v: f64, z: f64| ((v - vc) * tv + (z - zc) * tz, (z - zc) * tv - (v - vc) * tz);
        let rail = |v: f64| local(v, self.rail.profile.z(v));
        let wheel = |u: f64| {
            let (p, _) = self.wheel_section(pose, &fd, u);
            local(sg * p.y, p.z)
        };
        // Parameter of `curve` on `range` with τ = target, by Newton from `start`
        // (central-difference slope); None when it leaves the range.
        let solve = |curve: &dyn Fn(f64) -> (f64, f64), range: (f64, f64), start: f64, target: f64| {
            let mut p = start;
            for _ in 0..30 {
                let f = curve(p).0 - target;
                if f.abs() < 1e-13 {
                    return Some(p);
                }
                let h = 1e-7;
                let (a, b) = ((p - h).max(range.0), (p + h).min(range.1));
                let slope = (curve(b).0 - curve(a).0) / (b - a);
                if slope.is_nan() || slope.abs() <= 1e-6 {
                    return None;
                }
                let next = p - f / slope;
                if !(next >= range.0 && next <= range.1) {
                    return None;
                }
                p = next;
            }
            Some(p).filter(|&p| (curve(p).0 - target).abs() < 1e-10)
        };
        let k_half = ((half_width / spacing).round() as usize).max(2);
        let (rr, wr) = (self.rail.profile.y_range(), self.wheel.profile.y_range());
        let rho = |u: f64| self.wheel.nominal_radius - self.wheel.profile.z(u);
        let rho_c = rho(uc);
        let a0 = g.curvature_x.max(self.settings.min_relative_curvature);
        // March outward from the contact point in both directions.
        let mut samples: Vec<(f64, f64, f64)> = Vec::with_capacity(2 * k_half + 1);
        for dir in [-1.0, 1.0] {
            let (mut v, mut u) = (vc, uc);
            for k in 0..=k_half {
                if dir > 0.0 && k == 0 {
                    continue;
                }
                let tau = dir * spacing * k as f64;
                let (Some(v1), Some(u1)) = (solve(&rail, rr, v, tau), solve(&wheel, wr, u, tau)) else { break };
                (v, u) = (v1, u1);
                samples.push((tau, wheel(u).1 - rail(v).1, a0 * rho_c / rho(u)));
            }
        }
        samples.sort_by(|a, b| a.0.total_cmp(&b.0));
        let h0 = samples.iter().find(|s| s.0 == 0.0).map(|s| s.1).ok_or_else(|| {
            ContactError::InvalidInput("separation: the contact point is not on both profiles' cross-sections".into())
        })?;
        // Orient y with e2.
        let t3 = fd.rot * Vector3::new(0.0, sg * tv, tz);
        let flip = t3.dot(&g.e2) < 0.0;
        if flip {
            samples.reverse();
        }
        let sign = if flip { -1.0 } else { 1.0 };
        SampledSeparation::new(
            samples.iter().map(|s| sign * s.0).collect(),
            samples.iter().map(|s| s.1 - h0).collect(),
            samples.iter().map(|s| s.2).collect(),
        )
    }

    /// The relative lateral curvature `B` of Hertz's ellipse at contact `g`: the local one,
    /// except in conformal contact, where it is a small difference of two large curvatures
    /// (below [`CONFORMAL_CURVATURE_RATIO`] times the rail's curvature there). There it is
    /// not less than [`CONFORMAL_REGION_FACTOR`] times the curvature `δ/w²` of the parabola
    /// with the width `2w` of the rigid interpenetration region ([`Self::region_curvature`]).
    ///
    /// At the S1002 flange root on UIC 60 the profiles conform over a few millimetres: the
    /// local `B` jumps between −0.4 and 1.2 1/m from one 3 µm shift to the next, and with it
    /// Hertz's force at a given penetration (∝ B^−1/4 as B → 0), by up to a factor 2; the
    /// region's curvature changes smoothly (1.4 → 2.7 1/m), and with half of it the normal
    /// force lies 8–19 % below a Kik–Piotrowski patch's over that stretch, where the local
    /// `B` gave −12 % to +75 % (docs/validation.md, "The conformal stretch of the flange
    /// root"). Elsewhere the local curvature is the larger and is kept, and the rule is
    /// continuous where it starts to apply (the larger of two continuous curvatures).
    fn lateral_curvature(&self, pose: &WheelPose, g: &ContactGeometry) -> f64 {
        let b = g.curvature_y;
        if b >= CONFORMAL_CURVATURE_RATIO * self.rail.profile.curvature(g.params[1]).abs() || g.penetration <= 0.0 {
            return b;
        }
        self.region_curvature(pose, g).map_or(b, |br| b.max(CONFORMAL_REGION_FACTOR * br))
    }

    /// The curvature `δ/w²` of the parabola whose rigid interpenetration region `h(y) < δ`
    /// has the width `2w` of contact `g`'s, with `h` the undeformed separation across the
    /// contact ([`Self::separation`], sampled every 0.25 mm over ±12 mm, the ends of the
    /// region interpolated linearly, an end beyond 12 mm taken at 12 mm).
    pub fn region_curvature(&self, pose: &WheelPose, g: &ContactGeometry) -> Option<f64> {
        let (half, spacing) = (0.012, 2.5e-4);
        let s = self.separation(pose, g, half, spacing).ok()?;
        let d = g.penetration;
        let (lo, hi, _) = region_ends(&s, d)?;
        let w = 0.5 * (hi - lo);
        (w > 0.0).then(|| d / (w * w))
    }

    /// The rigid interpenetration region of loaded contact `g` (penetration > 0), the region
    /// CONTACT's patch rule compares ([`PatchCombination`]): where the undeformed separation
    /// across the contact ([`Self::separation`], sampled every [`KP_SEPARATION_SPACING`] over
    /// ±[`KP_SEPARATION_HALF_WIDTH`]) stays below the penetration, connected to the contact
    /// point, its ends interpolated linearly between the samples.
    pub fn interpenetration_region(
        &self,
        pose: &WheelPose,
        g: &ContactGeometry,
    ) -> Result<InterpenetrationRegion, ContactError> {
        self.region_and_separation(pose, g).map(|(r, _)| r)
    }

    /// [`Self::interpenetration_region`] and the separation it was found on.
    fn region_and_separation(
        &self,
        pose: &WheelPose,
        g: &ContactGeometry,
    ) -> Result<(InterpenetrationRegion, SampledSeparation), ContactError> {
        if g.penetration.is_nan() || g.penetration <= 0.0 {
            return Err(ContactError::InvalidInput(format!(
                "interpenetration region: penetration {:e} m, must be > 0",
                g.penetration
            )));
        }
        let sep = self.separation(pose, g, KP_SEPARATION_HALF_WIDTH, KP_SEPARATION_SPACING)?;
        let (lo, hi, truncated) = region_ends(&sep, g.penetration).ok_or_else(|| {
            ContactError::InvalidInput("interpenetration region: no sample at the contact point".into())
        })?;
        // the ends in the rail profile's plane (lateral coordinate v to the field side, height z)
        let sg = self.rail.side.sign();
        let fd = self.rail.frame_derivs(g.params[0]);
        let p = 0.5 * (g.point_rail + g.point_wheel);
        let section = |y: f64| {
            let l = fd.rot.transpose() * (p + g.e2 * y - fd.origin);
            (sg * l.y, l.z)
        };
        let (a, b) = (section(lo), section(hi));
        let ends = if a.0 <= b.0 { [a, b] } else { [b, a] };
        Ok((InterpenetrationRegion { lateral: (lo, hi), ends, truncated }, sep))
    }

    /// A scan minimum farther from the rail than this (a tenth of the seeds' gap limit) is
    /// separated: it carries no force and cannot touch within a step (its seed gets a short
    /// Newton search and no fall-back point).
    fn separated_gap(&self) -> f64 {
        0.1 * self.settings.scan_gap_limit
    }

    /// Seeds `(gap, q, u_lo, u_hi)` at the local minima of the scan gap, into `seeds`
    /// (`vals` is a buffer for the scan).
    fn scan(
        &self,
        pose: &WheelPose,
        s0: f64,
        fd: &RailFrameDerivs,
        vals: &mut Vec<(f64, [f64; 4])>,
        seeds: &mut Vec<(f64, [f64; 4], f64, f64)>,
    ) {
        let (lo, hi) = self.wheel.profile.y_range();
        let n = self.settings.scan_points.max(8);
        let u = |i: usize| lo + (hi - lo) * i as f64 / (n - 1) as f64;
        vals.clear();
        vals.extend((0..n).map(|i| self.scan_gap(pose, s0, fd, u(i), 1)));
        seeds.clear();
        for i in 1..n - 1 {
            let g = vals[i].0;
            let (before, after) = (vals[i - 1].0, vals[i + 1].0);
            // a separated minimum next to a point off the rail profile lies at its cut: no seed
            let at_cut = !(before.is_finite() && after.is_finite()) && g > self.separated_gap();
            if g.is_finite() && g <= before && g < after && g < self.settings.scan_gap_limit && !at_cut {
                seeds.push((g, vals[i].1, u(i - 1), u(i + 1)));
            }
        }
    }

    /// Golden-section refinement of the scan gap on `[a, b]` (fallback).
    fn refine_scan(&self, pose: &WheelPose, s0: f64, frame: &RailFrameDerivs, mut a: f64, mut b: f64) -> [f64; 4] {
        let gr = 0.5 * (5f64.sqrt() - 1.0);
        let f = |u: f64| self.scan_gap(pose, s0, frame, u, 4).0;
        let mut c = b - gr * (b - a);
        let mut d = a + gr * (b - a);
        let (mut fc, mut fd) = (f(c), f(d));
        for _ in 0..60 {
            if fc < fd {
                b = d;
                d = c;
                fd = fc;
                c = b - gr * (b - a);
                fc = f(c);
            } else {
                a = c;
                c = d;
                fc = fd;
                d = a + gr * (b - a);
                fd = f(d);
            }
        }
        self.scan_gap(pose, s0, frame, 0.5 * (a + b), 4).1
    }

    /// Whether Newton's solution `q` lies on both profiles and within 0.5 rad of the wheel
    /// circle's lowest point, whose angle is `lowest` ([`Self::lowest_angle`] at the wheel's
    /// station). The wheel angle `θ = q[3]` is measured in the wheel's body frame, which turns
    /// with the wheel as it rolls, so the bound applies to θ relative to the lowest point's
    /// angle (wrapped to ±π), not to θ itself: a bound on θ itself rejected every converged
    /// solution of a rolling wheel whose spin angle was beyond ±0.5 rad (about three quarters
    /// of the evaluations of a running car), and the search then took the scan's fall-back
    /// point under the wheel centre instead of the contact point.
    fn in_domain(&self, q: &[f64; 4], lowest: f64) -> bool {
        let (rl, rh) = self.rail.profile.y_range();
        let (wl, wh) = self.wheel.profile.y_range();
        let rel = (q[3] - lowest + std::f64::consts::PI).rem_euclid(std::f64::consts::TAU) - std::f64::consts::PI;
        q.iter().all(|x| x.is_finite()) && q[1] >= rl && q[1] <= rh && q[2] >= wl && q[2] <= wh && rel.abs() < 0.5
    }

    /// The wheel's body x and z axes in the rail frame `fd`.
    fn wheel_axes(pose: &WheelPose, fd: &RailFrameDerivs) -> (Vector3<f64>, Vector3<f64>) {
        let mt = fd.rot.transpose();
        (mt * pose.rotation.column(0), mt * pose.rotation.column(2))
    }

    /// The wheel angle θ (body frame) of the lowest point of the wheel's circles, from the
    /// wheel's body x and z axes `a`, `b` in the rail frame ([`Self::wheel_axes`]).
    fn lowest_angle(a: &Vector3<f64>, b: &Vector3<f64>) -> f64 {
        (-a.z).atan2(b.z)
    }

    /// Finds all potential contact points (local minima of the gap with a scan gap
    /// below [`ContactSettings::scan_gap_limit`]), including separated ones (negative
    /// penetration). Updates the warm-start state.
    pub fn find_geometry(&mut self, pose: &WheelPose) -> Result<Vec<ContactGeometry>, ContactError> {
        let mut out = Vec::new();
        self.find_geometry_into(pose, &mut out)?;
        Ok(out)
    }

    /// [`Self::find_geometry`] into `out` (cleared first), allocating nothing once the
    /// buffers have grown.
    fn find_geometry_into(&mut self, pose: &WheelPose, out: &mut Vec<ContactGeometry>) -> Result<(), ContactError> {
        out.clear();
        let (s0, fd0, lowest) = self.locate(pose)?;
        // Warm start only.
        if !self.settings.always_scan && !self.previous.is_empty() {
            let mut ok = true;
            for k in 0..self.previous.len() {
                match self.newton(pose, self.previous[k]) {
                    Ok(q) if self.in_domain(&q, lowest) => out.push(self.geometry_at(pose, q, ContactMethod::Newton)),
                    _ => {
                        ok = false;
                        break;
                    }
                }
            }
            if ok {
                self.dedup(out);
                self.remember(out);
                return Ok(());
            }
            out.clear();
        }
        let (mut vals, mut seeds) = (std::mem::take(&mut self.scratch.scan), std::mem::take(&mut self.scratch.seeds));
        self.scan(pose, s0, &fd0, &mut vals, &mut seeds);
        for &(gap, seed, ulo, uhi) in &seeds {
            // Prefer a previous solution close to this seed as the starting guess.
            let start = self.previous.iter().find(|p| (p[2] - seed[2]).abs() < 2e-3).copied().unwrap_or(seed);
            // A minimum separated by more than a tenth of the gap limit carries no force and
            // cannot touch within a step: Newton gets a quarter of the iterations, and when it
            // fails the seed is dropped (the scan finds it again as it closes). Measuring the gap
            // along the rail normal, the scan also sees the flange face across from the rail's
            // gauge face (1.5-2 mm apart in a curve), where Newton finds no stationary point; the
            // full fall-back path there cost a 3-degree curve run of two cars 3.4 times its wall
            // time (benches/train.rs). (The scan's gap is approximate, so a seed near touching,
            // either side, gets the full search.)
            let separated = gap > self.separated_gap();
            let iterations =
                if separated { self.settings.max_iterations.div_ceil(4) } else { self.settings.max_iterations };
            // a Newton solution from `from` that stays in the domain near this seed, and its
            // geometry when both relative curvatures are positive
            let converged = |from: [f64; 4]| {
                self.newton_within(pose, from, iterations)
                    .ok()
                    .filter(|q| self.in_domain(q, lowest) && (q[2] - seed[2]).abs() < 5e-3)
            };
            let convex = |q: [f64; 4]| {
                Some(self.geometry_at(pose, q, ContactMethod::Newton))
                    .filter(|g| g.curvature_x > 0.0 && g.curvature_y > 0.0)
            };
            let solved = converged(start).or_else(|| if start != seed { converged(seed) } else { None });
            let g = match solved.and_then(convex) {
                Some(g) => g,
                None if separated => continue,
                None => {
                    let q = self.refine_scan(pose, s0, &fd0, ulo, uhi);
                    // Newton once more from the refined scan point: when it converges the
                    // point is exact (and the same whichever start the search had), the scan
                    // point only approximate
                    converged(q)
                        .and_then(convex)
                        .unwrap_or_else(|| self.geometry_at(pose, q, ContactMethod::ScanFallback))
                }
            };
            out.push(g);
        }
        (self.scratch.scan, self.scratch.seeds) = (vals, seeds);
        self.dedup(out);
        self.remember(out);
        Ok(())
    }

    /// The wheel's station on the rail (kept as the station's warm start), the rail frame there
    /// (the scan's) and the wheel angle of the lowest point of the wheel's circles (the
    /// reference of the wheel angle bound, [`Self::in_domain`]).
    fn locate(&mut self, pose: &WheelPose) -> Result<(f64, RailFrameDerivs, f64), ContactError> {
        if !(pose.position.iter().all(|x| x.is_finite()) && pose.rotation.iter().all(|x| x.is_finite())) {
            return Err(ContactError::InvalidInput("non-finite wheel pose".into()));
        }
        let s0 = self.rail.station(&pose.position, self.last_station)?;
        self.last_station = Some(s0);
        let fd0 = self.rail.frame_derivs(s0);
        let (a0, b0) = Self::wheel_axes(pose, &fd0);
        Ok((s0, fd0, Self::lowest_angle(&a0, &b0)))
    }

    /// Keeps the points of a search as the warm start of the next one.
    fn remember(&mut self, points: &[ContactGeometry]) {
        self.previous.clear();
        self.previous.extend(points.iter().map(|g| g.params));
        self.previous_exact = points.iter().all(Self::exact);
    }

    /// A converged Newton solution with both relative curvatures positive (what the scan
    /// path accepts without falling back to the refined scan point).
    fn exact(g: &ContactGeometry) -> bool {
        g.method == ContactMethod::Newton && g.curvature_x > 0.0 && g.curvature_y > 0.0
    }

    /// The points of `pose` found by Newton from each warm-start point alone, into `out`:
    /// `false` (and `out` to be discarded) unless every one converges, stays on the profiles,
    /// is exact ([`Self::exact`]) and lies within [`PERTURBED_POINT_MOVE`] of where it started.
    fn follow_previous(&mut self, pose: &WheelPose, out: &mut Vec<ContactGeometry>) -> Result<bool, ContactError> {
        out.clear();
        if !self.previous_exact || self.previous.is_empty() {
            return Ok(false);
        }
        let (_, _, lowest) = self.locate(pose)?;
        for k in 0..self.previous.len() {
            let p = self.previous[k];
            let Ok(q) = self.newton(pose, p) else { return Ok(false) };
            let near = (q[1] - p[1]).abs() < PERTURBED_POINT_MOVE && (q[2] - p[2]).abs() < PERTURBED_POINT_MOVE;
            if !(near && self.in_domain(&q, lowest)) {
                return Ok(false);
            }
            let g = self.geometry_at(pose, q, ContactMethod::Newton);
            if !Self::exact(&g) {
                return Ok(false);
            }
            out.push(g);
        }
        Ok(true)
    }

    /// Keeps the deepest of points closer than the merge distance, then orders by `u`
    /// (in place; stable sorts, which do not allocate for the few points of a wheel).
    fn dedup(&self, v: &mut Vec<ContactGeometry>) {
        v.sort_by(|a, b| b.penetration.total_cmp(&a.penetration));
        let mut kept = 0;
        for i in 0..v.len() {
            let g = v[i];
            let dup = v[..kept].iter().any(|o| {
                (o.params[1] - g.params[1]).abs() < self.settings.merge_distance
                    && (o.params[2] - g.params[2]).abs() < self.settings.merge_distance
            });
            if !dup {
                v[kept] = g;
                kept += 1;
            }
        }
        v.truncate(kept);
        v.sort_by(|a, b| a.params[2].total_cmp(&b.params[2]));
    }

    /// The friction coefficient at contact parameters `q` (`q[0]` the distance along the
    /// rail, `q[1]` the rail profile's lateral coordinate): the map's when set, else
    /// `friction`.
    pub fn friction_at(&self, q: &[f64; 4]) -> f64 {
        self.friction_map.as_ref().map_or(self.friction, |m| m.mu(q[0], q[1]))
    }

    /// The pair's elastic constants for the patch and creep laws: the combined plane-strain
    /// modulus `E*` ([`combined_modulus`]), the combined shear modulus
    /// `G = 2/(1/G_wheel + 1/G_rail)` and the mean Poisson ratio, (Pa, Pa, 1).
    pub fn elastic_constants(&self) -> (f64, f64, f64) {
        let (wm, rm) = (&self.wheel_material, &self.rail_material);
        let g_mod = 2.0 / (1.0 / wm.shear_modulus() + 1.0 / rm.shear_modulus());
        (combined_modulus(wm, rm), g_mod, 0.5 * (wm.poisson + rm.poisson))
    }

    /// Contact points in contact (`δ > 0`) with normal and creep forces.
    pub fn evaluate(&mut self, pose: &WheelPose) -> Result<Vec<ContactPoint>, ContactError> {
        self.evaluate_cached(pose).map(<[ContactPoint]>::to_vec)
    }

    /// [`Self::evaluate`] leaving the warm start of the search as it was: an observation
    /// (recording loads between steps) then cannot change the next force evaluation's
    /// search, so results do not depend on how often they are recorded.
    pub fn observe(&mut self, pose: &WheelPose) -> Result<Vec<ContactPoint>, ContactError> {
        self.keeping_warm_start(|c| c.evaluate(pose))
    }

    /// Runs `f` and puts the search's warm start back as it was before: its points, whether
    /// they are exact, and the station.
    fn keeping_warm_start<T>(&mut self, f: impl FnOnce(&mut Self) -> T) -> T {
        let (exact, last_station) = (self.previous_exact, self.last_station);
        let mut saved = std::mem::take(&mut self.scratch.saved_previous);
        saved.clear();
        saved.extend_from_slice(&self.previous);
        let result = f(self);
        self.previous_exact = exact;
        self.last_station = last_station;
        self.previous.clear();
        self.previous.extend_from_slice(&saved);
        self.scratch.saved_previous = saved;
        result
    }

    /// [`Self::evaluate_cached`] at a pose within a finite-difference perturbation of the last
    /// evaluated one (a Jacobian column), leaving the warm start as it was. When every point
    /// of the last search was an exact Newton solution, each is followed by Newton alone from
    /// where it was; the search is the full one (as [`Self::evaluate_cached`]) when one of them
    /// was a scan fall-back, or when following one fails, moves it more than
    /// [`PERTURBED_POINT_MOVE`], takes it off the profiles or makes it non-convex. The points
    /// followed are the stationary points of the gap the full search finds (to the Newton
    /// tolerance), so the difference quotient keeps the forces' change with the pose; the
    /// profile scan, the bulk of an evaluation, runs once per Jacobian instead of once per
    /// column.
    pub fn evaluate_perturbed(&mut self, pose: &WheelPose) -> Result<&[ContactPoint], ContactError> {
        let search = |c: &mut Self, pose: &WheelPose, out: &mut Vec<ContactGeometry>| {
            if c.follow_previous(pose, out)? { Ok(()) } else { c.find_geometry_into(pose, out) }
        };
        self.keeping_warm_start(|c| c.evaluate_into_scratch(pose, search))?;
        Ok(self.scratch.points.as_slice())
    }

    /// [`Self::evaluate`] into a buffer of the contact, allocating nothing once the
    /// buffers have grown; the points stay valid until the next call.
    pub fn evaluate_cached(&mut self, pose: &WheelPose) -> Result<&[ContactPoint], ContactError> {
        self.evaluate_into_scratch(pose, Self::find_geometry_into)?;
        Ok(self.scratch.points.as_slice())
    }

    /// The geometry of `pose` by `search`, then its loaded points, into the contact's buffers
    /// (`scratch.geometry`, `scratch.points`), allocating nothing once they have grown.
    fn evaluate_into_scratch(
        &mut self,
        pose: &WheelPose,
        search: impl FnOnce(&mut Self, &WheelPose, &mut Vec<ContactGeometry>) -> Result<(), ContactError>,
    ) -> Result<(), ContactError> {
        let (mut geoms, mut out) =
            (std::mem::take(&mut self.scratch.geometry), std::mem::take(&mut self.scratch.points));
        let result = search(self, pose, &mut geoms).and_then(|()| self.loaded_points(pose, &geoms, None, &mut out));
        (self.scratch.geometry, self.scratch.points) = (geoms, out);
        result
    }

    /// [`Self::evaluate`] with prescribed creepages (the same at every point, CONTACT's
    /// "creepage prescribed" mode) instead of the kinematic ones; the creep forces come from
    /// the patch model's patch (the strips of a Kik–Piotrowski patch for FASTSIM).
    pub fn evaluate_with_creepages(
        &mut self,
        pose: &WheelPose,
        creepages: &Creepages,
    ) -> Result<Vec<ContactPoint>, ContactError> {
        let mut geoms = Vec::new();
        self.find_geometry_into(pose, &mut geoms)?;
        let mut out = Vec::new();
        self.loaded_points(pose, &geoms, Some(creepages), &mut out)?;
        Ok(out)
    }

    /// The Kik–Piotrowski patch of contact `g` at its penetration (module
    /// [`super::kik_piotrowski`]; separation sampled every 0.05 mm over ±25 mm).
    pub fn kik_piotrowski_patch(
        &self,
        pose: &WheelPose,
        g: &ContactGeometry,
        epsilon: f64,
        strips: usize,
    ) -> Result<KpPatch, ContactError> {
        let sep = self.separation(pose, g, KP_SEPARATION_HALF_WIDTH, KP_SEPARATION_SPACING)?;
        let e_star = combined_modulus(&self.wheel_material, &self.rail_material);
        KpPatch::at_penetration(&sep, g.penetration, epsilon, strips, e_star)
    }

    /// The geometries in contact (`δ > 0`) with their normal and creep forces, into `out`:
    /// one patch per point, then combined by [`ContactSettings::patch_combination`].
    fn loaded_points(
        &self,
        pose: &WheelPose,
        geoms: &[ContactGeometry],
        prescribed: Option<&Creepages>,
        out: &mut Vec<ContactPoint>,
    ) -> Result<(), ContactError> {
        self.loaded_points_separate(pose, geoms, prescribed, out)?;
        if self.settings.patch_combination != PatchCombination::Separate {
            self.combine_patches(pose, geoms, prescribed, out)?;
        }
        Ok(())
    }

    /// [`Self::loaded_points`], one patch per point.
    fn loaded_points_separate(
        &self,
        pose: &WheelPose,
        geoms: &[ContactGeometry],
        prescribed: Option<&Creepages>,
        out: &mut Vec<ContactPoint>,
    ) -> Result<(), ContactError> {
        out.clear();
        if let PatchModel::KikPiotrowski { epsilon, strips } = self.patch_model {
            return self.loaded_points_kp(pose, geoms, prescribed, epsilon, strips, out);
        }
        let (e_star, g_mod, nu) = self.elastic_constants();
        for &g in geoms.iter().filter(|g| g.penetration > 0.0) {
            let kmin = self.settings.min_relative_curvature;
            let hertz =
                HertzConstants::new(g.curvature_x.max(kmin), self.lateral_curvature(pose, &g).max(kmin), e_star)?;
            let p = 0.5 * (g.point_rail + g.point_wheel);
            let r = p - pose.position;
            let v = pose.velocity + pose.angular_velocity.cross(&r);
            let pen_rate = -v.dot(&g.normal);
            let fe = hertz.force(g.penetration);
            let fn_ = (fe * (1.0 + self.damping * pen_rate)).max(0.0);
            let speed = pose.velocity.norm().max(self.settings.min_speed);
            let creepages = prescribed.copied().unwrap_or(Creepages {
                longitudinal: v.dot(&g.e1) / speed,
                lateral: v.dot(&g.e2) / speed,
                spin: pose.angular_velocity.dot(&g.normal) / speed,
            });
            let (a, b) = hertz.semi_axes(fn_);
            let creep = creep_forces(self.creep_model, &creepages, a, b, fn_, self.friction_at(&g.params), g_mod, nu);
            out.push(ContactPoint {
                geometry: g,
                hertz,
                semi_axes: (a, b),
                penetration_rate: pen_rate,
                normal_force: fn_,
                creepages,
                creep,
                patch: None,
            });
        }
        Ok(())
    }

    /// [`Self::loaded_points`] with Kik–Piotrowski patches. A contact point that lies inside
    /// the patch of a deeper one (CONTACT's one wide patch where the search finds two
    /// points) is dropped: the deeper point's patch covers it.
    fn loaded_points_kp(
        &self,
        pose: &WheelPose,
        geoms: &[ContactGeometry],
        prescribed: Option<&Creepages>,
        epsilon: f64,
        strips: usize,
        out: &mut Vec<ContactPoint>,
    ) -> Result<(), ContactError> {
        self.patch_model.validate()?;
        let (e_star, g_mod, nu) = self.elastic_constants();
        let kmin = self.settings.min_relative_curvature;
        let mut loaded: Vec<(ContactGeometry, KpPatch)> = Vec::new();
        for &g in geoms.iter().filter(|g| g.penetration > 0.0) {
            loaded.push((g, self.kik_piotrowski_patch(pose, &g, epsilon, strips)?));
        }
        // deepest first; drop points inside an already kept patch
        loaded.sort_by(|a, b| b.0.penetration.total_cmp(&a.0.penetration));
        let mut kept: Vec<(ContactGeometry, KpPatch)> = Vec::new();
        for (g, patch) in loaded {
            let p = 0.5 * (g.point_rail + g.point_wheel);
            let covered = kept.iter().any(|(k, kp)| {
                let y = (p - 0.5 * (k.point_rail + k.point_wheel)).dot(&k.e2);
                y >= kp.lateral_extent.0 && y <= kp.lateral_extent.1
            });
            if !covered {
                kept.push((g, patch));
            }
        }
        kept.sort_by(|a, b| a.0.params[2].total_cmp(&b.0.params[2]));
        for (g, patch) in kept {
            let hertz = HertzConstants::new(g.curvature_x.max(kmin), g.curvature_y.max(kmin), e_star)?;
            let p = 0.5 * (g.point_rail + g.point_wheel);
            let r = p - pose.position;
            let v = pose.velocity + pose.angular_velocity.cross(&r);
            let pen_rate = -v.dot(&g.normal);
            let fn_ = (patch.normal_force * (1.0 + self.damping * pen_rate)).max(0.0);
            let patch = patch.scaled_to(fn_);
            let speed = pose.velocity.norm().max(self.settings.min_speed);
            let creepages = prescribed.copied().unwrap_or(Creepages {
                longitudinal: v.dot(&g.e1) / speed,
                lateral: v.dot(&g.e2) / speed,
                spin: pose.angular_velocity.dot(&g.normal) / speed,
            });
            let creep = patch.creep(self.creep_model, &creepages, self.friction_at(&g.params), g_mod, nu);
            out.push(ContactPoint {
                geometry: g,
                hertz,
                semi_axes: patch.equivalent_ellipse(),
                penetration_rate: pen_rate,
                normal_force: fn_,
                creepages,
                creep,
                patch: Some(patch.summary()),
            });
        }
        Ok(())
    }
}

/// A contact is conformal where its relative lateral curvature is below this fraction of the
/// rail profile's curvature at the point ([`WheelRailContact::lateral_curvature`]).
pub const CONFORMAL_CURVATURE_RATIO: f64 = 0.1;
/// In conformal contact Hertz's lateral curvature is at least this fraction of the curvature of
/// the parabola with the rigid interpenetration region's width
/// ([`WheelRailContact::lateral_curvature`]).
pub const CONFORMAL_REGION_FACTOR: f64 = 0.5;

/// How far a contact point may move (rail and wheel lateral coordinates) under a Jacobian
/// column's perturbation and still be followed by Newton alone
/// ([`WheelRailContact::evaluate_perturbed`]), m. The perturbations move a point by about their
/// own size (1e-7 m); a larger move means another point of the gap, found by the full search.
pub const PERTURBED_POINT_MOVE: f64 = 1e-4;

/// Half-width of the separation sampled for a Kik–Piotrowski patch, m.
pub const KP_SEPARATION_HALF_WIDTH: f64 = 0.025;
/// Spacing of the separation samples of a Kik–Piotrowski patch, m.
pub const KP_SEPARATION_SPACING: f64 = 5e-5;

/// The ends `(lo, hi, truncated)` along the separation's `y` of the region `h(y) < d` connected
/// to the sample at `y = 0`, each interpolated linearly between the samples; an end beyond the
/// sampled range is the last sample (`truncated`).
fn region_ends(s: &SampledSeparation, d: f64) -> Option<(f64, f64, bool)> {
    let i0 = s.y.iter().position(|&y| y == 0.0)?;
    let mut truncated = false;
    // the crossing h = d from sample i0 outward in direction `step` (±1), or the last sample
    let mut end = |step: isize| {
        let mut i = i0 as isize;
        loop {
            let j = i + step;
            if j < 0 || j as usize >= s.y.len() {
                truncated = true;
                return s.y[i as usize];
            }
            let (hi_, hj) = (s.h[i as usize], s.h[j as usize]);
            if hj >= d {
                let t = (d - hi_) / (hj - hi_);
                return s.y[i as usize] + t * (s.y[j as usize] - s.y[i as usize]);
            }
            i = j;
        }
    };
    let hi = end(1);
    let lo = end(-1);
    Some((lo, hi, truncated))
}

/// Convex curvature tensor of a surface in the basis `(e1, e2)` of the common tangent
/// plane. `sign = −1` when `n` is the outward normal of the surface, `+1` when `−n` is.
#[allow(clippy::too_many_arguments)]
fn curvature_tensor(
    r1: &Vector3<f64>,
    r2: &Vector3<f64>,
    r11: &Vector3<f64>,
    r12: &Vector3<f64>,
    r22: &Vector3<f64>,
    n: &Vector3<f64>,
    e1: &Vector3<f64>,
    e2: &Vector3<f64>,
    sign: f64,
) -> nalgebra::Matrix2<f64> {
    // Coordinates (α, β) of e in the parameter basis: least squares with the metric.
    let gm = nalgebra::Matrix2::new(r1.dot(r1), r1.dot(r2), r1.dot(r2), r2.dot(r2));
    let inv = gm.try_inverse().unwrap_or_else(nalgebra::Matrix2::zeros);
    let coords = |e: &Vector3<f64>| inv * nalgebra::Vector2::new(r1.dot(e), r2.dot(e));
    let (l, m, nn) = (r11.dot(n), r12.dot(n), r22.dot(n));
    let ii = |x: nalgebra::Vector2<f64>, y: nalgebra::Vector2<f64>| {
        sign * (x[0] * y[0] * l + (x[0] * y[1] + x[1] * y[0]) * m + x[1] * y[1] * nn)
    };
    let (c1, c2) = (coords(e1), coords(e2));
    let k12 = ii(c1, c2);
    nalgebra::Matrix2::new(ii(c1, c1), k12, k12, ii(c2, c2))
}
