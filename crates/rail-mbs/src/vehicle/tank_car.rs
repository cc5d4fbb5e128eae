//! The tank car builder and its parameters.

use std::sync::Arc;

use nalgebra::{Matrix3, Vector3};

use crate::mbs::{
    BodyId, BrakeTorque, Bushing, JointKind, Multibody, RigidBody, SpeedProfile, SpringDamper, SpringLaw, Table,
    TrajectoryDriver, WheelsetContact, WheelsetReport,
};
use crate::profile::{Profile, s1002_wheel, uic60_rail};
use crate::track::{Side, Track};
use crate::wheel_rail::{RailGeometry, RailPath, WheelGeometry, WheelPose, WheelRailContact};
use ancf_core::error::{AncfError, check_positive, invalid};

/// Mass and principal moments of inertia (body axes: x forward, y left, z up) of a body.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct BodyMass {
    /// Mass, kg.
    pub mass: f64,
    /// `[Ixx, Iyy, Izz]` about the centre of mass, kg·m².
    pub inertia: [f64; 3],
}

/// Linear suspension element: stiffness and damping along the track-frame axes
/// `(x forward, y left, z up)`.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct SuspensionParams {
    /// Stiffness `[kx, ky, kz]`, N/m.
    pub stiffness: [f64; 3],
    /// Damping `[cx, cy, cz]`, N·s/m.
    pub damping: [f64; 3],
}

/// Wheel/rail contact parameters.
#[derive(Debug, Clone)]
pub struct ContactParams {
    /// Wheel profile (crate convention). Default: S1002 (EN 13715), the profile with an
    /// exact published definition; an approximate AAR-1B is available in
    /// [`crate::profile::aar1b_wheel_approx`].
    pub wheel_profile: Profile,
    /// Rail profile. Default: UIC 60.
    pub rail_profile: Profile,
    /// Lateral distance from the wheelset centre to the wheel profile origin, m.
    /// Default 0.75 m (S1002 taping line with a 1360 mm back-to-back distance).
    pub wheel_profile_offset: f64,
    /// Track gauge used to place the rail profiles, m. Default: the track's gauge.
    pub gauge: Option<f64>,
    /// Depth of the gauge point below the rail crown, m. Default 0.014 (EN 13848).
    pub gauge_depth: f64,
    /// Rail inward cant on a straight track, rad (on a curved [`Track`] the track's own
    /// rail cant is used). Default 1/40.
    pub straight_rail_cant: f64,
    /// Friction coefficient. Default 0.3.
    pub friction: f64,
    /// Friction over the rail profile and along the track (a lubricated gauge face, a wet
    /// stretch: [`crate::wheel_rail::FrictionMap`]); `None` (the default): `friction`
    /// everywhere.
    pub friction_map: Option<Arc<crate::wheel_rail::FrictionMap>>,
    /// Hunt–Crossley normal damping `d`, s/m. Default 50 s/m (dimensionless `d·δ̇`
    /// ≈ 0.05 at 1 mm/s).
    pub damping: f64,
    /// Samples of the profile scan. Default 200.
    pub scan_points: usize,
    /// Scan the profiles at every evaluation (robust: sees a new contact point such as the
    /// flange appear) or only when the warm-started Newton solutions fail (faster; enough
    /// on tangent track). Default true.
    pub always_scan: bool,
}

impl ContactParams {
    /// Defaults (S1002 on UIC 60).
    pub fn standard() -> Result<Self, AncfError> {
        let err = |e: crate::profile::ProfileError| invalid("profile", e, "a valid profile");
        Ok(Self {
            wheel_profile: s1002_wheel(5e-4).map_err(err)?,
            rail_profile: uic60_rail(5e-4).map_err(err)?,
            wheel_profile_offset: 0.75,
            gauge: None,
            gauge_depth: 0.014,
            straight_rail_cant: 1.0 / 40.0,
            friction: 0.3,
            friction_map: None,
            damping: 50.0,
            scan_points: 200,
            always_scan: true,
        })
    }
}

/// Parameters of the freight tank car of seed 000 §8.1. Every default is documented
/// with its source; "assumed" marks engineering choices where no source was found
/// (see `../shared/notes/rail-vehicle-and-contact.md` §4: the exact DOT-111/117 truck
/// and car data are not public).
#[derive(Debug, Clone)]
pub struct TankCarParams {
    /// Tank length (cylindrical part plus heads), m. Default 12 (seed 000 §8.1).
    pub tank_length: f64,
    /// Tank radius, m. Default 1.5 (seed 000 §8.1).
    pub tank_radius: f64,
    /// Height of the tank axis above the top of rail, m. Default 2.35 (assumed: tank
    /// bottom 0.85 m above the rail, on the stub sills).
    pub tank_axis_height: f64,
    /// Tank body (shell, fittings) without lading. Default 15 000 kg (assumed: a
    /// 12.7 mm steel shell of this size weighs about 13 t), thin-shell inertia.
    pub tank: BodyMass,
    /// Rigid lading added to the tank body (kg, centre height above the tank axis, m).
    /// Default none (the fluid is modelled separately).
    pub lading: Option<(f64, f64)>,
    /// Length along the tank axis over which the rigid lading is spread uniformly, centred
    /// on the tank's mid-length, m: it adds `m L²/12` to the tank's pitch and yaw inertia
    /// (a liquid frozen in the tank fills its whole length). Default 0: a point mass.
    pub lading_length: f64,
    /// Mass carried in the tank but modelled as separate bodies (the ANCF fluid), kg: it
    /// counts in the suspension preloads and the static wheel loads. Default 0.
    pub carried_mass: f64,
    /// Each stub sill. Default 1200 kg (assumed).
    pub stub_sill: BodyMass,
    /// Distance between the bogie (truck) centres, m. Default 9.0 (assumed for a 12 m
    /// tank).
    pub truck_centers: f64,
    /// Bogie wheelbase, m. Default 1.829 (72 in, Barber truck of mbsim-wagons).
    pub wheelbase: f64,
    /// Nominal wheel radius, m. Default 0.457 (914 mm wheels, seed 000 §8.1).
    pub wheel_radius: f64,
    /// Wheelset. Default 1777.6 kg, inertia 1179.6 / 138 / 1179.6 kg·m² (axle along y;
    /// mbsim-wagons Barber truck).
    pub wheelset: BodyMass,
    /// Bolster. Default 911 kg, 509 / 25 / 511 kg·m² (mbsim-wagons Barber truck).
    pub bolster: BodyMass,
    /// Bogie frame (the two side frames as one body). Default 630 kg (mbsim-wagons
    /// side-frame pair), inertia of two 2.5 m beams at ±1 m. With
    /// [`TruckModel::ThreePiece`] each side frame is its own body with half this mass, at
    /// ±`journal_half_span` ([`TankCarParams::side_frame`]).
    pub frame: BodyMass,
    /// How the bogie is built: seed 000's rigid frame (default) or a warp-capable
    /// three-piece freight truck ([`TruckModel`]).
    pub truck: TruckModel,
    /// Each equalizer. Default 120 kg, 1.9 m long beam (assumed).
    pub equalizer: BodyMass,
    /// Lateral half-distance of the axle boxes / journal bearings, m. Default 1.0.
    pub journal_half_span: f64,
    /// Lateral half-distance of the secondary suspension, m. Default 0.8 (assumed).
    pub secondary_half_span: f64,
    /// Primary suspension, per axle box (frame – wheelset). Default k = (10, 5, 20) MN/m,
    /// c = (10, 10, 20) kN·s/m (assumed: stiff adapter pads of a three-piece truck).
    pub primary: SuspensionParams,
    /// Journal bearing, per bearing (equalizer – wheelset). Default k = 20 MN/m each
    /// axis, c = 1 kN·s/m; roll and yaw stiffness 0.1 MN·m/rad (assumed).
    pub journal: SuspensionParams,
    /// Rotational stiffness of a journal bearing about x and z, N·m/rad.
    pub journal_tilt_stiffness: f64,
    /// Secondary suspension, per side (bolster – stub sill). Default k = (5, 1, 2) MN/m,
    /// c = (50, 20, 20) kN·s/m (assumed; car bounce ≈ 2 Hz loaded).
    pub secondary: SuspensionParams,
    /// Coupler height above the rail, m, and distance of the coupler face from the tank
    /// centre, m. Default 0.87 m and 7.0 m (assumed).
    pub coupler_height: f64,
    /// See [`TankCarParams::coupler_height`].
    pub coupler_reach: f64,
    /// Wheel/rail contact.
    pub contact: ContactParams,
}

/// How a bogie (truck) of [`add_tank_car`] is built. Both have the same masses, springs and
/// dampers; they differ in what the two side frames can do.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum TruckModel {
    /// Seed 000's bogie: both side frames are one rigid frame on the four axle boxes (primary
    /// suspension), turning on a centre pin under the bolster, which carries the stub sill on
    /// the secondary suspension. A twist of the track within the bogie (one wheel lower than
    /// the plane of the other three) is taken by the stiff primary springs and moves wheel
    /// load: about ±46 % of the static load per 1.7 mm (docs/validation.md, "Findings on
    /// irregular track").
    #[default]
    RigidFrame,
    /// Three-piece freight truck: a left and a right side frame, each on its own two axle
    /// boxes (primary suspension, with the journal bearing's roll stiffness
    /// `journal_tilt_stiffness` at each adapter), carry the bolster on the load springs (the
    /// `secondary` parameters, one nest per side frame, at ±`journal_half_span`, preloaded by
    /// the car body and the bolster); the bolster turns in the centre bowl (a revolute joint
    /// about the vertical) under the stub sill. The side frames pitch independently, so the
    /// truck warps: a twist within the bogie changes its wheel loads only through the load
    /// springs. The load springs sit under the side frames (not at `secondary_half_span`),
    /// so the car body's roll stiffness on its trucks is that of a three-piece truck,
    /// (journal/secondary half span)² times the rigid frame's.
    ThreePiece,
}

impl TruckModel {
    /// The scene / Python name: `"rigid_frame"` or `"three_piece"`.
    pub fn name(self) -> &'static str {
        match self {
            Self::RigidFrame => "rigid_frame",
            Self::ThreePiece => "three_piece",
        }
    }

    /// The model named `name` ([`TruckModel::name`]); the error names the field `truck`.
    pub fn from_name(name: &str) -> Result<Self, AncfError> {
        match name {
            "rigid_frame" => Ok(Self::RigidFrame),
            "three_piece" => Ok(Self::ThreePiece),
            other => Err(invalid("truck", other, "'rigid_frame' or 'three_piece'")),
        }
    }
}

fn beam(mass: f64, length: f64) -> BodyMass {
    let i = mass * length * length / 12.0;
    BodyMass { mass, inertia: [0.01 * i + 1.0, i, i] }
}

/// Depth of the tank's half-ellipsoidal heads, m ([`ancf_core::mesh::TANK_CAR_HEAD_DEPTH`], our
/// choice: seed 000 gives none); the heads lie within the overall `tank_length`. Python reads it
/// as `railslosh.mesh.TANK_CAR_HEAD_DEPTH`.
pub const TANK_HEAD_DEPTH: f64 = ancf_core::mesh::TANK_CAR_HEAD_DEPTH;

impl TankCarParams {
    /// The liquid of this car's tank (shell `tank_length − 2·TANK_HEAD_DEPTH` between
    /// [`TANK_HEAD_DEPTH`] heads, radius `tank_radius`) filled to the volume fraction `fill`,
    /// meshed with `counts` elements (length, width, height).
    pub fn tank_spec(&self, fill: f64, counts: [usize; 3]) -> ancf_core::mesh::CylinderTankSpec {
        ancf_core::mesh::CylinderTankSpec {
            length: self.tank_length - 2.0 * TANK_HEAD_DEPTH,
            radius: self.tank_radius,
            head_depth: TANK_HEAD_DEPTH,
            fill,
            n_length: counts[0],
            n_width: counts[1],
            n_height: counts[2],
            grading: 1.0,
        }
    }

    /// The defaults listed on each field.
    pub fn standard() -> Result<Self, AncfError> {
        let (m, r, l): (f64, f64, f64) = (15_000.0, ancf_core::mesh::TANK_CAR_RADIUS, ancf_core::mesh::TANK_CAR_LENGTH);
        let shell = BodyMass {
            mass: m,
            inertia: [m * r * r, m * (r * r / 2.0 + l * l / 12.0), m * (r * r / 2.0 + l * l / 12.0)],
        };
        Ok(Self {
            tank_length: l,
            tank_radius: r,
            tank_axis_height: 2.35,
            tank: shell,
            lading: None,
            lading_length: 0.0,
            carried_mass: 0.0,
            stub_sill: BodyMass { mass: 1200.0, inertia: [60.0, 250.0, 250.0] },
            truck_centers: 9.0,
            wheelbase: 1.829,
            wheel_radius: 0.457,
            wheelset: BodyMass { mass: 1777.6, inertia: [1179.6, 138.0, 1179.6] },
            bolster: BodyMass { mass: 911.0, inertia: [509.0, 25.0, 511.0] },
            frame: BodyMass { mass: 630.0, inertia: [630.0, 328.0, 958.0] },
            truck: TruckModel::RigidFrame,
            equalizer: beam(120.0, 1.9),
            journal_half_span: 1.0,
            secondary_half_span: 0.8,
            primary: SuspensionParams { stiffness: [10e6, 5e6, 20e6], damping: [10e3, 10e3, 20e3] },
            journal: SuspensionParams { stiffness: [20e6; 3], damping: [1e3; 3] },
            journal_tilt_stiffness: 1e5,
            secondary: SuspensionParams { stiffness: [5e6, 1e6, 2e6], damping: [50e3, 20e3, 20e3] },
            coupler_height: 0.87,
            coupler_reach: 7.0,
            contact: ContactParams::standard()?,
        })
    }

    /// One side frame of a [`TruckModel::ThreePiece`] truck: half of [`TankCarParams::frame`],
    /// its roll and yaw inertia about its own centre by the parallel-axis theorem (the pair's
    /// side frames lie at ±`journal_half_span`), at least 1 % of its pitch inertia.
    pub fn side_frame(&self) -> BodyMass {
        let m = 0.5 * self.frame.mass;
        let d2 = self.journal_half_span * self.journal_half_span;
        let iy = 0.5 * self.frame.inertia[1];
        let own = |i: f64| (0.5 * i - m * d2).max(0.01 * iy);
        BodyMass { mass: m, inertia: [own(self.frame.inertia[0]), iy, own(self.frame.inertia[2])] }
    }

    /// Height of the tank body's centre of mass (its frame origin) above the tank axis, m:
    /// nonzero with rigid lading off the axis.
    pub fn tank_origin_above_axis(&self) -> f64 {
        self.lading.map_or(0.0, |(m, h)| m * h / (self.tank.mass + m).max(1e-300))
    }

    /// Total mass of the car, kg.
    pub fn total_mass(&self) -> f64 {
        self.tank.mass
            + self.lading.map_or(0.0, |l| l.0)
            + self.carried_mass
            + 2.0 * self.stub_sill.mass
            + 2.0 * (self.bolster.mass + self.frame.mass + 2.0 * self.equalizer.mass + 2.0 * self.wheelset.mass)
    }

    /// Checks every field; errors name the field and the allowed range.
    pub fn validate(&self) -> Result<(), AncfError> {
        for (f, v) in [
            ("tank_length", self.tank_length),
            ("tank_radius", self.tank_radius),
            ("tank_axis_height", self.tank_axis_height),
            ("truck_centers", self.truck_centers),
            ("wheelbase", self.wheelbase),
            ("wheel_radius", self.wheel_radius),
            ("journal_half_span", self.journal_half_span),
            ("secondary_half_span", self.secondary_half_span),
            ("coupler_reach", self.coupler_reach),
            ("coupler_height", self.coupler_height),
        ] {
            check_positive(f, v)?;
        }
        if self.wheelbase >= self.truck_centers {
            return Err(invalid("wheelbase", self.wheelbase, "below truck_centers"));
        }
        if self.tank_axis_height <= self.tank_radius {
            return Err(invalid(
                "tank_axis_height",
                self.tank_axis_height,
                "above tank_radius (tank clear of the rail)",
            ));
        }
        for (name, b) in [
            ("tank", self.tank),
            ("stub_sill", self.stub_sill),
            ("wheelset", self.wheelset),
            ("bolster", self.bolster),
            ("frame", self.frame),
            ("equalizer", self.equalizer),
        ] {
            check_positive(&format!("{name}.mass"), b.mass)?;
            for (k, i) in b.inertia.iter().enumerate() {
                check_positive(&format!("{name}.inertia[{k}]"), *i)?;
            }
        }
        if !(self.carried_mass.is_finite() && self.carried_mass >= 0.0) {
            return Err(invalid("carried_mass", self.carried_mass, "finite, >= 0 kg"));
        }
        if let Some((m, _)) = self.lading
            && !(m.is_finite() && m >= 0.0)
        {
            return Err(invalid("lading mass", m, "finite, >= 0 kg"));
        }
        if !(self.lading_length.is_finite()
            && self.lading_length >= 0.0
            && self.lading_length <= 2.0 * self.tank_length)
        {
            return Err(invalid(
                "lading_length",
                self.lading_length,
                &format!("finite, 0 to twice the tank length ({} m)", 2.0 * self.tank_length),
            ));
        }
        for (name, s) in [("primary", self.primary), ("journal", self.journal), ("secondary", self.secondary)] {
            for (k, v) in s.stiffness.iter().chain(&s.damping).enumerate() {
                if !(v.is_finite() && *v >= 0.0) {
                    return Err(invalid(&format!("{name} stiffness/damping[{k}]"), v, "finite, >= 0"));
                }
            }
        }
        let c = &self.contact;
        if !(c.friction.is_finite() && (0.0..=1.0).contains(&c.friction)) {
            return Err(invalid("contact.friction", c.friction, "[0, 1]"));
        }
        if !(c.damping.is_finite() && c.damping >= 0.0) {
            return Err(invalid("contact.damping", c.damping, "finite, >= 0 s/m"));
        }
        if c.scan_points < 20 {
            return Err(invalid("contact.scan_points", c.scan_points, ">= 20"));
        }
        Ok(())
    }
}

/// Body ids and contact indices of one car in a [`Multibody`].
#[derive(Debug, Clone, PartialEq)]
pub struct CarBodies {
    /// Car name prefix.
    pub name: String,
    /// Tank (car body).
    pub tank: BodyId,
    /// Stub sills (front, rear).
    pub stub_sills: [BodyId; 2],
    /// Bolsters (front, rear bogie).
    pub bolsters: [BodyId; 2],
    /// Bogie frames `[bogie][left, right]`: the rigid frame twice ([`TruckModel::RigidFrame`])
    /// or the two side frames ([`TruckModel::ThreePiece`]).
    pub frames: [[BodyId; 2]; 2],
    /// Equalizers `[bogie][left, right]`.
    pub equalizers: [[BodyId; 2]; 2],
    /// Wheelsets, front to rear.
    pub wheelsets: [BodyId; 4],
    /// Index of each wheelset's contact in [`Multibody::wheelsets`].
    pub contacts: [usize; 4],
    /// Index of the trajectory joint, if the car is driven.
    pub trajectory: Option<usize>,
    /// Indices of the brake force elements (one per wheelset), if any.
    pub brakes: Vec<usize>,
    /// Static load of each wheel on level track, N.
    pub static_wheel_load: f64,
    /// Tank-centre arc length at `t = 0`, m.
    pub station: f64,
}

/// Vertical load (along the track up axis) and lateral force of one wheel.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct WheelLoad {
    /// Vertical wheel load `Q` (≥ 0), N.
    pub vertical: f64,
    /// Lateral force `Y` on the wheel along the track-left axis, N.
    pub lateral: f64,
    /// Number of contact points.
    pub points: usize,
}

/// Wheel loads `[left, right]` of a wheelset from its contact report, in the track
/// frame at the wheelset (`up`, `left` axes).
pub fn wheel_loads(report: &WheelsetReport, up: &Vector3<f64>, left: &Vector3<f64>) -> [WheelLoad; 2] {
    [0, 1].map(|s| {
        let f = report.wheel_force(s);
        WheelLoad { vertical: f.dot(up), lateral: f.dot(left), points: report.points[s].len() }
    })
}

/// Places a body-local offset `(dx along track, dy left, dz up)` relative to station `s`.
struct Placer<'a> {
    track: &'a Track,
    speed: f64,
}

impl Placer<'_> {
    fn body(&self, name: String, m: BodyMass, s: f64, dy: f64, dz: f64) -> RigidBody {
        let f = self.track.frame(s);
        let mut b = RigidBody::new(&name, m.mass, m.inertia, f.to_global(&Vector3::new(0.0, dy, dz)));
        b.orientation = f.rotation;
        b.velocity = f.tangent() * self.speed;
        b.angular_velocity = f.up() * (self.speed * self.track.curvature(s));
        b
    }
}

#[allow(clippy::too_many_arguments)] // private helper; every argument is a distinct physical input
fn bushing(
    mb: &Multibody,
    name: String,
    i: BodyId,
    j: BodyId,
    at: Vector3<f64>,
    axes: Matrix3<f64>,
    s: &SuspensionParams,
    preload: Vector3<f64>,
) -> Bushing {
    let si = mb.initial_state(Some(i));
    let sj = mb.initial_state(Some(j));
    Bushing {
        name,
        bodies: [Some(i), Some(j)],
        points: [si.rotation.transpose() * (at - si.position), sj.rotation.transpose() * (at - sj.position)],
        frame_i: si.rotation.transpose() * axes,
        frame_j: sj.rotation.transpose() * axes,
        offset: Vector3::zeros(),
        stiffness: s.stiffness,
        damping: s.damping,
        preload,
        rotational_stiffness: [0.0; 3],
        rotational_damping: [0.0; 3],
        free_axis: None,
        matrix_stiffness: None,
        matrix_damping: None,
    }
}

/// Wheel/rail contact pair of one wheel.
fn contact_pair(p: &TankCarParams, track: &Arc<Track>, side: Side) -> Result<WheelRailContact, AncfError> {
    let c = &p.contact;
    let gauge = c.gauge.unwrap_or(track.gauge());
    let offset = RailGeometry::offset_for_gauge(&c.rail_profile, gauge, c.gauge_depth)
        .ok_or_else(|| invalid("contact.gauge_depth", c.gauge_depth, "within the rail profile's depth"))?;
    let straight = track.points().iter().all(|t| t.curvature == 0.0 && t.superelevation == 0.0 && t.grade == 0.0);
    // the straight-rail shortcut has no irregularity: an irregular track takes the track path
    let path = if straight && track_is_at_origin(track) && track.irregularity().is_none() {
        RailPath::Straight { inward_cant: c.straight_rail_cant }
    } else {
        RailPath::Track(track.clone())
    };
    let mut w = WheelRailContact::new(
        WheelGeometry {
            profile: c.wheel_profile.clone(),
            nominal_radius: p.wheel_radius,
            profile_offset: c.wheel_profile_offset,
            side,
        },
        RailGeometry { profile: c.rail_profile.clone(), side, profile_offset: offset, vertical_offset: 0.0, path },
    );
    w.friction = c.friction;
    w.friction_map = c.friction_map.clone();
    w.damping = c.damping;
    w.settings.scan_points = c.scan_points;
    w.settings.always_scan = c.always_scan;
    Ok(w)
}

fn track_is_at_origin(track: &Track) -> bool {
    let f = track.frame(0.0);
    f.origin.norm() < 1e-12 && (f.rotation - Matrix3::identity()).norm() < 1e-12
}

/// Height of the wheelset centre above the track centreline at which the wheels carry
/// `load` each (Hertzian deflection included), found from the contact geometry.
fn wheelset_height(pair: &mut [WheelRailContact; 2], frame_s: &crate::track::TrackFrame, r0: f64, load: f64) -> f64 {
    let mut z = r0;
    for _ in 0..4 {
        let pose = WheelPose::at_rest(frame_s.to_global(&Vector3::new(0.0, 0.0, z)), frame_s.rotation);
        let mut worst: Option<(f64, f64)> = None;
        for w in pair.iter_mut() {
            w.reset();
            if let Ok(g) = w.find_geometry(&pose)
                && let Some(best) = g.iter().max_by(|a, b| a.penetration.total_cmp(&b.penetration))
            {
                let e_star = crate::wheel_rail::combined_modulus(&w.wheel_material, &w.rail_material);
                let k = w.settings.min_relative_curvature;
                let target =
                    crate::wheel_rail::HertzConstants::new(best.curvature_x.max(k), best.curvature_y.max(k), e_star)
                        .map(|h| h.penetration(load))
                        .unwrap_or(0.0);
                if worst.is_none_or(|(p, _)| best.penetration - target < p) {
                    worst = Some((best.penetration - target, target));
                }
            }
        }
        let Some((excess, _)) = worst else { break };
        z += excess;
        if excess.abs() < 1e-9 {
            break;
        }
    }
    for w in pair.iter_mut() {
        w.reset();
    }
    z
}

/// Where and how a car starts.
#[derive(Debug, Clone)]
pub struct CarPlacement {
    /// Arc length of the tank centre at `t = 0`, m.
    pub station: f64,
    /// Initial speed along the track, m/s.
    pub speed: f64,
    /// Speed profile the tank centre is held to by a trajectory joint, if any.
    pub drive: Option<SpeedProfile>,
    /// Brake torque (N·m against s) applied to every wheelset (reaction on its bogie
    /// frame), if any.
    pub brake: Option<Table>,
}

/// Adds one tank car to `mb`, placed and moving as `placement` says.
pub fn add_tank_car(
    mb: &mut Multibody,
    name: &str,
    params: &TankCarParams,
    track: &Arc<Track>,
    placement: CarPlacement,
) -> Result<CarBodies, AncfError> {
    let CarPlacement { station, speed, drive, brake } = placement;
    params.validate()?;
    if !speed.is_finite() {
        return Err(invalid("speed", speed, "finite, m/s"));
    }
    let p = params;
    let g = mb.gravity.norm();
    let place = Placer { track, speed };
    let r0 = p.wheel_radius;
    let tank_mass = BodyMass {
        mass: p.tank.mass + p.lading.map_or(0.0, |l| l.0),
        inertia: match p.lading {
            // Lading at its height above the tank axis (parallel axes), spread uniformly over
            // `lading_length` along the axis (a rod: m L²/12 in pitch and yaw).
            Some((m, h)) => {
                let rod = m * p.lading_length * p.lading_length / 12.0;
                [p.tank.inertia[0] + m * h * h, p.tank.inertia[1] + m * h * h + rod, p.tank.inertia[2] + rod]
            }
            None => p.tank.inertia,
        },
    };
    let lading_shift = p.tank_origin_above_axis();
    let tank =
        mb.add_body(place.body(format!("{name}/tank"), tank_mass, station, 0.0, p.tank_axis_height + lading_shift))?;
    let half = 0.5 * p.truck_centers;
    let sill_z = p.tank_axis_height - p.tank_radius;
    let mut stub_sills = [tank; 2];
    let mut bolsters = [tank; 2];
    let mut frames = [[tank; 2]; 2];
    let mut equalizers = [[tank; 2]; 2];
    let mut wheelsets = [tank; 4];
    let mut contacts = [0; 4];
    // Static loads on level track.
    let body_weight = (tank_mass.mass + p.carried_mass + 2.0 * p.stub_sill.mass) * g;
    let per_bogie = 0.5 * body_weight;
    let per_axlebox = 0.25 * (per_bogie + (p.bolster.mass + p.frame.mass) * g);
    let per_bearing = 0.5 * p.equalizer.mass * g;
    let wheel_load = 0.5 * (2.0 * per_axlebox + 2.0 * per_bearing + p.wheelset.mass * g);
    let car = CarFrame {
        name,
        p,
        track,
        place: &place,
        sill_z,
        tank,
        r0,
        per_bogie,
        per_axlebox,
        per_bearing,
        wheel_load,
        speed,
    };
    for (b, sign) in [(0usize, 1.0), (1, -1.0)] {
        (stub_sills[b], bolsters[b], frames[b], equalizers[b]) =
            add_bogie(mb, &car, b, station + sign * half, &mut wheelsets, &mut contacts)?;
    }
    let trajectory = match drive {
        Some(profile) => {
            profile.validate()?;
            let f = track.frame(station);
            let driver = TrajectoryDriver { track: track.clone(), s0: station, speed: profile };
            Some(mb.add_joint(
                &format!("{name}/trajectory"),
                JointKind::Trajectory(driver),
                Some(tank),
                None,
                f.to_global(&Vector3::new(0.0, 0.0, p.tank_axis_height + lading_shift)),
                f.rotation,
            )?)
        }
        None => None,
    };
    let mut brakes = Vec::new();
    if let Some(torque) = brake {
        // The brake's reaction goes to the frame; on a three-piece truck half to each side frame
        // (the brake beams are guided in both).
        let reactions: &[&str] = match p.truck {
            TruckModel::RigidFrame => &[""],
            TruckModel::ThreePiece => &["L", "R"],
        };
        let share = reactions.len() as f64;
        let torque = Table { x: torque.x.clone(), y: torque.y.iter().map(|y| y / share).collect() };
        for (k, ws) in wheelsets.iter().enumerate() {
            for (side, frame) in reactions.iter().zip(frames[k / 2]) {
                brakes.push(mb.add_force(Box::new(BrakeTorque {
                    name: format!("{name}/brake{}{side}", k + 1),
                    bodies: [Some(*ws), Some(frame)],
                    axis: Vector3::y(),
                    torque: torque.clone(),
                    smoothing: 0.5,
                    speed_factor: None,
                }))?);
            }
        }
    }
    Ok(CarBodies {
        name: name.to_string(),
        tank,
        stub_sills,
        bolsters,
        frames,
        equalizers,
        wheelsets,
        contacts,
        trajectory,
        brakes,
        static_wheel_load: wheel_load,
        station,
    })
}

/// What [`add_tank_car`] has fixed before it builds its bogies ([`add_bogie`]).
#[derive(Clone, Copy)]
struct CarFrame<'a> {
    name: &'a str,
    p: &'a TankCarParams,
    track: &'a Arc<Track>,
    place: &'a Placer<'a>,
    sill_z: f64,
    tank: BodyId,
    r0: f64,
    per_bogie: f64,
    per_axlebox: f64,
    per_bearing: f64,
    wheel_load: f64,
    speed: f64,
}

/// Bogie `b` (0 front, 1 rear) of [`add_tank_car`], centred at track station `sb`: its stub sill
/// fixed to the tank, bolster, frame (or side frames, [`TruckModel`]), equalizers and two
/// wheelsets with their suspensions and wheel/rail contacts (written into `wheelsets` and
/// `contacts` at 2b + w). Returns (stub sill, bolster, frames `[left, right]`, equalizers).
fn add_bogie(
    mb: &mut Multibody,
    car: &CarFrame,
    b: usize,
    sb: f64,
    wheelsets: &mut [BodyId; 4],
    contacts: &mut [usize; 4],
) -> Result<(BodyId, BodyId, [BodyId; 2], [BodyId; 2]), AncfError> {
    let CarFrame { name, p, track, place, sill_z, tank, r0, per_bogie, per_axlebox, per_bearing, wheel_load, speed } =
        *car;
    let frame_sb = track.frame(sb);
    let axes = frame_sb.rotation;
    let bn = format!("{name}/bogie{}", b + 1);
    let sill = mb.add_body(place.body(format!("{name}/stub_sill{}", b + 1), p.stub_sill, sb, 0.0, sill_z))?;
    mb.add_joint(
        &format!("{name}/stub_sill{}-tank", b + 1),
        JointKind::Fixed,
        Some(sill),
        Some(tank),
        frame_sb.to_global(&Vector3::new(0.0, 0.0, sill_z)),
        axes,
    )?;
    let bolster = mb.add_body(place.body(format!("{bn}/bolster"), p.bolster, sb, 0.0, 0.6))?;
    let sides = [(0usize, 1.0), (1, -1.0)];
    let frames = match p.truck {
        TruckModel::RigidFrame => {
            let frame = mb.add_body(place.body(format!("{bn}/frame"), p.frame, sb, 0.0, 0.45))?;
            mb.add_joint(
                &format!("{bn}/pin"),
                JointKind::Revolute,
                Some(bolster),
                Some(frame),
                frame_sb.to_global(&Vector3::new(0.0, 0.0, 0.55)),
                axes,
            )?;
            for (k, side) in sides {
                let at = frame_sb.to_global(&Vector3::new(0.0, side * p.secondary_half_span, 0.75));
                let preload = Vector3::new(0.0, 0.0, 0.5 * per_bogie);
                let bu = bushing(mb, format!("{bn}/secondary{k}"), bolster, sill, at, axes, &p.secondary, preload);
                mb.add_force(Box::new(bu))?;
            }
            [frame; 2]
        }
        TruckModel::ThreePiece => {
            mb.add_joint(
                &format!("{bn}/centre_bowl"),
                JointKind::Revolute,
                Some(sill),
                Some(bolster),
                frame_sb.to_global(&Vector3::new(0.0, 0.0, 0.75)),
                axes,
            )?;
            let mut frames = [bolster; 2];
            for (k, side) in sides {
                let y = side * p.journal_half_span;
                let lr = if k == 0 { "L" } else { "R" };
                frames[k] = mb.add_body(place.body(format!("{bn}/side_frame{lr}"), p.side_frame(), sb, y, 0.45))?;
                let at = frame_sb.to_global(&Vector3::new(0.0, y, 0.6));
                let preload = Vector3::new(0.0, 0.0, 0.5 * (per_bogie + p.bolster.mass * mb.gravity.norm()));
                let bu =
                    bushing(mb, format!("{bn}/load_springs{k}"), frames[k], bolster, at, axes, &p.secondary, preload);
                mb.add_force(Box::new(bu))?;
            }
            frames
        }
    };
    let mut eq = [tank; 2];
    for (k, side) in sides {
        eq[k] = mb.add_body(place.body(
            format!("{bn}/equalizer{}", if k == 0 { "L" } else { "R" }),
            p.equalizer,
            sb,
            side * p.journal_half_span,
            r0,
        ))?;
    }
    for (w, wsign) in [(0usize, 1.0), (1, -1.0)] {
        let sw = sb + wsign * 0.5 * p.wheelbase;
        let fw = track.frame(sw);
        let mut pair = [contact_pair(p, track, Side::Left)?, contact_pair(p, track, Side::Right)?];
        let z = wheelset_height(&mut pair, &fw, r0, wheel_load);
        let mut ws = place.body(format!("{bn}/wheelset{}", w + 1), p.wheelset, sw, 0.0, z);
        ws.angular_velocity += fw.lateral() * (speed / r0);
        let ws = mb.add_body(ws)?;
        let idx = 2 * b + w;
        wheelsets[idx] = ws;
        for (k, side) in sides {
            let at = fw.to_global(&Vector3::new(0.0, side * p.journal_half_span, z));
            let pre = Vector3::new(0.0, 0.0, -per_axlebox);
            let mut bu =
                bushing(mb, format!("{bn}/primary{}{k}", w + 1), frames[k], ws, at, fw.rotation, &p.primary, pre);
            if p.truck == TruckModel::ThreePiece {
                // The side frame's pedestal roof on the bearing adapter holds it upright: its
                // two axle boxes lie on one line, along which springs alone give no roll
                // stiffness.
                bu.rotational_stiffness = [p.journal_tilt_stiffness, 0.0, 0.0];
                bu.free_axis = Some(1);
            }
            mb.add_force(Box::new(bu))?;
            let pre = Vector3::new(0.0, 0.0, -per_bearing);
            let mut jb = bushing(mb, format!("{bn}/journal{}{k}", w + 1), eq[k], ws, at, fw.rotation, &p.journal, pre);
            jb.rotational_stiffness = [p.journal_tilt_stiffness, 0.0, p.journal_tilt_stiffness];
            jb.free_axis = Some(1);
            mb.add_force(Box::new(jb))?;
        }
        contacts[idx] = mb.add_wheelset_contact(WheelsetContact {
            name: format!("{bn}/wheelset{}", w + 1),
            body: ws,
            wheels: pair,
        })?;
    }
    Ok((sill, bolster, frames, eq))
}

/// Joins the rear of `front` to the front of `rear` with a coupler (linear
/// spring–damper–actuator along the line between the coupler faces; defaults of seed
/// 000 §8.2 when `stiffness`/`damping` are `None`). Returns the force-element index;
/// its output is the coupler force, positive in tension.
pub fn add_coupler(
    mb: &mut Multibody,
    name: &str,
    params: &TankCarParams,
    front: &CarBodies,
    rear: &CarBodies,
    stiffness: Option<f64>,
    damping: Option<f64>,
) -> Result<usize, AncfError> {
    let sf = mb.initial_state(Some(front.tank));
    let sr = mb.initial_state(Some(rear.tank));
    // Tank-body points are relative to its centre of mass, which rigid lading moves off the
    // axis; the coupler stays at its height above the rail.
    let z = params.coupler_height - params.tank_axis_height - params.tank_origin_above_axis();
    let pf = Vector3::new(-params.coupler_reach, 0.0, z);
    let pr = Vector3::new(params.coupler_reach, 0.0, z);
    let free_length = (sr.point(&pr) - sf.point(&pf)).norm();
    if free_length < 1e-3 {
        return Err(invalid("coupler", free_length, "cars placed so that the coupler faces are >= 1 mm apart"));
    }
    let sd = SpringDamper {
        name: name.to_string(),
        bodies: [Some(front.tank), Some(rear.tank)],
        points: [pf, pr],
        free_length,
        law: SpringLaw::Linear {
            stiffness: stiffness.unwrap_or(SpringDamper::COUPLER_STIFFNESS),
            damping: damping.unwrap_or(SpringDamper::COUPLER_DAMPING),
        },
        actuator: None,
    };
    sd.validate()?;
    mb.add_force(Box::new(sd))
}
