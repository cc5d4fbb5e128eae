//! One typed description of a slosh run (issue 18): the liquid, its tank, the motion and the
//! discretization, with the library's defaults, built into a [`SloshSystem`] and started as a
//! [`SloshRun`] here, in Rust, where it is tested. The Python binding (`run_slosh`) only fills
//! it from its `scenario` dict.

use ancf_core::FluidBody;
use ancf_core::constitutive::Fluid;
use ancf_core::contact::{ContactPointRule, WALL_DAMPING_RATIO, WallContact, WallContactLaw};
use ancf_core::element::QuadratureOptions;
use ancf_core::error::{AncfError, invalid};
use ancf_core::mesh::FluidMesh;
use ancf_core::tank::{Bulkhead, TankGeometry, TankShape};

use super::system::PENETRATION_LIMIT_FACTOR;
use super::{PrescribedMotion, SloshFrame, SloshRun, SloshSystem, StepperChoice};
use crate::defaults::{GRAVITY, slosh_params};
use crate::integrator::{CheckpointFile, ExplicitParams, IntegratorError};

/// A slosh run's model: [`SloshScenario::new`] gives the defaults of every field.
#[derive(Debug, Clone)]
pub struct SloshScenario {
    /// The liquid's mesh in its reference configuration (tank frame).
    pub mesh: FluidMesh,
    /// The liquid.
    pub fluid: Fluid,
    /// The tank's shape and bulkheads.
    pub tank: TankShape,
    /// Bulkheads across the tank.
    pub bulkheads: Vec<Bulkhead>,
    /// The tank's motion. Default: at rest.
    pub motion: PrescribedMotion,
    /// Gravity, m/s². Default: (0, 0, −g).
    pub gravity: [f64; 3],
    /// The frame the liquid is solved in. Default: inertial (moving walls).
    pub frame: SloshFrame,
    /// Quadrature of the elements. Default: the library's (3³ force points, 4³ mass points).
    pub quadrature: QuadratureOptions,
    /// Wall-contact points per boundary-face edge. Default: the wall law's (3).
    pub contact_points_per_edge: usize,
    /// Where on a face the contact points sit. Default: Gauss points.
    pub contact_point_rule: ContactPointRule,
    /// Wall stiffness as a multiple of the default penalty law, the damping ratio kept
    /// (damping × factor^1.5). Default 1.
    pub contact_stiffness_factor: f64,
    /// Damping ratio of the liquid column on the wall spring. Default
    /// [`WALL_DAMPING_RATIO`].
    pub wall_damping_ratio: f64,
    /// Suction an adhesive wall holds on the wetted liquid, in units of the hydrostatic
    /// pressure at the bottom ρ g H ([`WallContactLaw::with_adhesion`]). Default 0: a
    /// unilateral wall.
    pub wall_adhesion: f64,
    /// Largest relative volume error a step may have. Default 0.01 (`f64::INFINITY`: none).
    pub volume_tolerance: f64,
    /// Largest wall penetration as a fraction of the smallest element edge. Default
    /// [`PENETRATION_LIMIT_FACTOR`] (`f64::INFINITY`: none).
    pub penetration_limit: f64,
}

impl SloshScenario {
    /// The scenario with every default ([`SloshScenario`]'s field docs).
    pub fn new(mesh: FluidMesh, fluid: Fluid, tank: TankShape) -> Self {
        Self {
            mesh,
            fluid,
            tank,
            bulkheads: Vec::new(),
            motion: PrescribedMotion::at_rest([0.0; 3]),
            gravity: [0.0, 0.0, -GRAVITY],
            frame: SloshFrame::Inertial,
            quadrature: QuadratureOptions::default(),
            contact_points_per_edge: WallContactLaw::default_for(1.0, 1.0, 1.0).points_per_edge,
            contact_point_rule: ContactPointRule::Gauss,
            contact_stiffness_factor: 1.0,
            wall_damping_ratio: WALL_DAMPING_RATIO,
            wall_adhesion: 0.0,
            volume_tolerance: 0.01,
            penetration_limit: PENETRATION_LIMIT_FACTOR,
        }
    }

    /// Checks the fields that the builders below do not check themselves.
    pub fn validate(&self) -> Result<(), AncfError> {
        for (field, x) in [("volume_tolerance", self.volume_tolerance), ("penetration_limit", self.penetration_limit)] {
            if x.is_nan() || x <= 0.0 {
                return Err(invalid(field, x, "a number > 0 (inf disables the check)"));
            }
        }
        let k = self.contact_stiffness_factor;
        if !(k.is_finite() && k > 0.0) {
            return Err(invalid("contact_stiffness_factor", k, "a finite number > 0"));
        }
        Ok(())
    }

    /// The liquid's depth at rest in the mesh (free surface − lowest node), at least 1 mm.
    pub fn depth(&self) -> f64 {
        self.mesh.liquid_depth().max(1e-3)
    }

    /// The wall law: the default penalty for this liquid's depth and gravity, with the damping
    /// ratio, the adhesion (its suction from the default stiffness), the stiffness factor (damping × factor^1.5, the ratio kept) and the contact points.
    pub fn wall_law(&self) -> Result<WallContactLaw, AncfError> {
        let g = self.gravity.iter().map(|x| x * x).sum::<f64>().sqrt().max(1e-3);
        let (rho, depth) = (self.fluid.density, self.depth());
        let mut law = WallContactLaw::default_for(rho, g, depth)
            .with_damping_ratio(self.wall_damping_ratio, rho, g, depth)?
            .with_adhesion(self.wall_adhesion, rho, g, depth)?;
        law.stiffness *= self.contact_stiffness_factor;
        law.damping *= self.contact_stiffness_factor.powf(1.5);
        law.points_per_edge = self.contact_points_per_edge;
        law.point_rule = self.contact_point_rule;
        Ok(law)
    }

    /// The system: body, tank, wall contact, motion and the per-step guards.
    pub fn build_system(&self) -> Result<SloshSystem, AncfError> {
        self.validate()?;
        let body = FluidBody::new(self.mesh.clone(), self.fluid, self.quadrature)?;
        let geo = TankGeometry::new(self.tank, self.bulkheads.clone())?;
        let contact = WallContact::new(&body, geo, self.wall_law()?)?;
        let mut sys = SloshSystem::new(body, contact, self.motion.clone(), self.gravity, self.frame)?;
        sys.volume_tolerance = self.volume_tolerance;
        sys.penetration_limit *= self.penetration_limit / PENETRATION_LIMIT_FACTOR;
        Ok(sys)
    }

    /// Starts the run of this scenario with the stepper `choice` for recorded steps of `h`
    /// (the library's stepper parameters), or continues the run saved in the checkpoint file
    /// `resume_from` bit for bit. Returns the run and why it uses its stepper.
    pub fn start(
        &self,
        choice: StepperChoice,
        h: f64,
        resume_from: Option<&std::path::Path>,
    ) -> Result<(SloshRun, String), AncfError> {
        let sys = self.build_system()?;
        let (implicit, explicit) = (slosh_params(), ExplicitParams::default());
        let run_error = |e: IntegratorError| AncfError::NonFinite { what: e.to_string(), element: 0 };
        let Some(path) = resume_from else {
            return SloshRun::with_choice(sys, 0.0, choice, h, implicit, explicit).map_err(run_error);
        };
        let bytes = CheckpointFile::read_bytes(path)
            .map_err(|e| invalid("resume_from", path.display(), &format!("a checkpoint file ({e})")))?;
        let run = SloshRun::resume_from_bytes(sys, &bytes, implicit, explicit).map_err(|e| {
            invalid("resume_from", path.display(), &format!("a checkpoint of a run of this same scene ({e})"))
        })?;
        let used = run.stepper.name();
        let asked = match choice {
            StepperChoice::Implicit => "implicit",
            StepperChoice::Explicit => "explicit",
            StepperChoice::Auto => used,
        };
        if asked != used {
            return Err(invalid(
                "stepper",
                asked,
                &format!("\"{used}\" or \"auto\": the checkpoint in resume_from is of an {used} run"),
            ));
        }
        Ok((run, format!("resumed: {used}")))
    }
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::defaults::liquid;
    use ancf_core::constitutive::Rheology;
    use ancf_core::mesh::box_mesh;

    fn box_scenario() -> SloshScenario {
        let l = [0.416, 0.324, 0.132];
        let lo = [-0.5 * l[0], -0.5 * l[1], 0.0];
        let mesh = box_mesh(lo, l, [2, 2, 2]).unwrap();
        let fluid = liquid(998.0, Rheology::Newtonian { viscosity: 1e-3 }, l[2], l[2] / 2.0).unwrap();
        SloshScenario::new(mesh, fluid, TankShape::Box { min: lo, max: [-lo[0], -lo[1], 0.3] })
    }

    #[test]
    fn the_systems_mass_product_is_the_pattern_product_bit_for_bit() {
        use crate::integrator::MechanicalSystem;
        let mut sys = box_scenario().build_system().unwrap();
        let n = sys.n_coords();
        let pattern = sys.pattern().dynamics;
        let mut m = vec![0.0; pattern.len()];
        sys.mass(&vec![0.0; n], &mut m).unwrap();
        let mut entries: Vec<(usize, usize, usize)> =
            sys.mass_entries().unwrap().into_iter().map(|k| (pattern[k].0, pattern[k].1, k)).collect();
        entries.sort_unstable();
        let a: Vec<f64> = (0..n).map(|i| (0.61 * i as f64).cos() * 7.0).collect();
        let (scale, start) = (1.37, (0..n).map(|i| 1e-3 * i as f64).collect::<Vec<_>>());
        let mut by_pattern = start.clone();
        for &(i, j, k) in &entries {
            by_pattern[i] -= scale * m[k] * a[j];
        }
        let mut own = start.clone();
        assert!(sys.subtract_mass_product(&m, &a, scale, &mut own));
        assert!(by_pattern.iter().zip(&own).all(|(x, y)| x.to_bits() == y.to_bits()));
        assert!(by_pattern.iter().zip(&start).any(|(x, y)| (x - y).abs() > 1.0), "a product far from zero");
    }

    #[test]
    fn the_wall_law_scales_stiffness_and_keeps_the_damping_ratio() {
        let mut sc = box_scenario();
        let base = sc.wall_law().unwrap();
        sc.contact_stiffness_factor = 4.0;
        sc.contact_points_per_edge = 5;
        let law = sc.wall_law().unwrap();
        assert!((law.stiffness / base.stiffness - 4.0).abs() < 1e-12);
        assert!((law.damping / base.damping - 8.0).abs() < 1e-12, "damping × 4^1.5");
        assert_eq!(law.points_per_edge, 5);
        sc.wall_damping_ratio = 1.0;
        assert!((sc.wall_law().unwrap().damping / law.damping - 10.0).abs() < 1e-9, "ζ 0.1 → 1");
    }

    #[test]
    fn the_guards_and_bad_fields_reach_the_system_or_an_error_naming_them() {
        let mut sc = box_scenario();
        let default = sc.build_system().unwrap().penetration_limit;
        sc.penetration_limit = 2.0 * PENETRATION_LIMIT_FACTOR;
        sc.volume_tolerance = 0.05;
        let sys = sc.build_system().unwrap();
        assert!((sys.penetration_limit / default - 2.0).abs() < 1e-12);
        assert_eq!(sys.volume_tolerance, 0.05);
        sc.contact_stiffness_factor = -1.0;
        let msg = sc.build_system().unwrap_err().to_string();
        assert!(msg.starts_with("invalid `contact_stiffness_factor` = -1: expected"), "{msg}");
    }

    #[test]
    fn a_started_run_is_the_run_built_by_hand() {
        let sc = box_scenario();
        let (mut run, why) = sc.start(StepperChoice::Implicit, 0.01, None).unwrap();
        assert_eq!(why, "requested: implicit");
        run.run_to(0.05, 0.01).unwrap();
        let mut by_hand = SloshRun::new(sc.build_system().unwrap(), 0.0, slosh_params()).unwrap();
        by_hand.run_to(0.05, 0.01).unwrap();
        assert_eq!(run.stepper.q(), by_hand.stepper.q());
        let missing = std::path::Path::new("/nonexistent/checkpoint.bin");
        let err = sc.start(StepperChoice::Auto, 0.01, Some(missing)).err().expect("a missing checkpoint");
        assert!(err.to_string().starts_with("invalid `resume_from`"), "{err}");
    }
}
