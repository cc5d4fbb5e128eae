//! The fluid train: the liquid cargo ([`FluidCargo`]), building a train whose tanks carry it
//! ([`build_fluid_train`]), and its run and record ([`run_fluid_train`], [`FluidTrainRecord`]) on
//! the one train run loop (`vehicle::run::drive`). The coupled system itself, [`FluidVehicle`],
//! is the parent module.

use ancf_core::constitutive::Fluid;
use ancf_core::contact::WallContactLaw;
use ancf_core::element::QuadratureOptions;
use ancf_core::mesh::{cylinder_tank, cylinder_tank_compartments};
use ancf_core::tank::{Bulkhead, TankGeometry};

use super::*;
use crate::integrator::{Hht, IntegratorError};
use crate::vehicle::run::{
    Cargo, Observer, RunFailure, RunResult, SampleSink, TrainRecord, TrainRun, TrainScenario, build_train, drive,
    record_sample, run_vehicle,
};
use crate::vehicle::tank_car::CarBodies;

/// Liquid cargo of every car of a train: an ANCF fluid mesh of the car's tank
/// (cylinder with half-ellipsoid heads 0.5 m deep, overall length `tank_length`).
#[derive(Debug, Clone)]
pub struct FluidCargo {
    /// The fluid, with its penalty parameters.
    pub fluid: Fluid,
    /// Elements along the length, across the width and over the height.
    pub counts: [usize; 3],
    /// Fill fraction of the tank height (0, 1).
    pub fill: f64,
    /// Bulkheads `(x, thickness)` in the tank frame, m.
    pub bulkheads: Vec<(f64, f64)>,
    /// Quadrature of the fluid elements.
    pub quadrature: QuadratureOptions,
    /// Wall stiffness as a multiple of the default `k_p = 1000 ρ g` (damping scaled by its
    /// 3/2 power, keeping the damping ratio), see `transverse_model` in `railslosh_cases::slosh`.
    pub wall_stiffness_factor: f64,
    /// Contact points per edge of each boundary face.
    pub contact_points_per_edge: usize,
    /// Damping ratio of the liquid column on the wall spring
    /// ([`ancf_core::contact::WallContactLaw::with_damping_ratio`]); default
    /// [`ancf_core::contact::WALL_DAMPING_RATIO`].
    pub wall_damping_ratio: f64,
    /// Suction an adhesive wall holds on the wetted liquid, in units of ρ g H
    /// ([`ancf_core::contact::WallContactLaw::with_adhesion`]); default 0 (unilateral).
    pub wall_adhesion: f64,
    /// How the coupled Newton matrix is solved ([`FluidVehicle::linear_solver`]); default
    /// [`LinearSolverKind::Condensed`].
    pub linear_solver: LinearSolverKind,
    /// Give a fluid without its own shear stabilization the recommended one
    /// ([`crate::defaults::default_shear_stabilization`] for the element height, liquid depth /
    /// `counts[2]`, with the floor of a tank with heads): the zero-energy-mode control that
    /// makes the rest state stable (docs/validation.md, "A stable rest state"). Default false,
    /// the library's bare
    /// discretization that the validation cases measure; scenes and `railslosh.vehicle.run_fluid`
    /// default to true.
    pub shear_stabilization: bool,
}

impl FluidCargo {
    /// The default discretization of the vehicle studies: 4³ penalty points and 4×4 contact
    /// points per boundary face with the default wall law. On the cylinder cross-section
    /// (`slosh-cylinder-half`) this raises the smallest eigenvalue of the rest state from
    /// λ = −88 (3³, 3×3) to −1.8 at the same cost per step in the coupled car runs; the fully
    /// stable choice there (walls 100× stiffer) collapsed the step size of the coupled braking
    /// run at t = 1.24 s, and 10× stiffer walls doubled its cost (docs/validation.md).
    pub fn new(fluid: Fluid, counts: [usize; 3], fill: f64, bulkheads: Vec<(f64, f64)>) -> Self {
        Self {
            fluid,
            counts,
            fill,
            bulkheads,
            quadrature: QuadratureOptions { penalty: 4, ..QuadratureOptions::default() },
            wall_stiffness_factor: 1.0,
            contact_points_per_edge: 4,
            wall_damping_ratio: ancf_core::contact::WALL_DAMPING_RATIO,
            wall_adhesion: 0.0,
            linear_solver: LinearSolverKind::Condensed,
            shear_stabilization: false,
        }
    }
}

/// Results of a train run with fluid cargo.
#[derive(Debug, Clone, Default)]
pub struct FluidTrainRecord {
    /// The vehicle results (wheel loads, couplers, tanks).
    pub train: TrainRecord,
    /// Fluid centre of mass in the tank frame, m: `[sample][car]`.
    pub oil_com_tank: Vec<Vec<[f64; 3]>>,
    /// Fluid centre of mass, global, m: `[sample][car]`.
    pub oil_com_global: Vec<Vec<[f64; 3]>>,
    /// Fluid load on the tank (contact force), tank frame, N: `[sample][car]`.
    pub fluid_force_tank: Vec<Vec<[f64; 3]>>,
    /// Relative fluid volume change: `[sample][car]`.
    pub volume_error: Vec<Vec<f64>>,
    /// Run-time invariants of each car's fluid at each sample ([`crate::invariants`], the last
    /// accepted step): largest wall gap of a node, contact point or the centre of mass (m),
    /// `[sample][car]`.
    pub containment_gap: Vec<Vec<f64>>,
    /// Smallest volume ratio J at any quadrature or check point, `[sample][car]`.
    pub min_volume_ratio: Vec<Vec<f64>>,
    /// Energy growth ε of the fluid's energy account, `[sample][car]`.
    pub energy_error: Vec<Vec<f64>>,
    /// Fluid mesh snapshots: time and the nodal coordinates of every car's fluid (global,
    /// the layout of `FluidBody` coordinates: 12 per node, position first).
    pub snapshots: Vec<(f64, Vec<Vec<f64>>)>,
    /// Fluid mass per car, kg.
    pub fluid_mass: f64,
    /// Fluid elements per car.
    pub elements: usize,
    /// Element-node table of each car's fluid mesh (node order A..H, docs/frames.md), for
    /// writing the snapshots as hexahedra.
    pub connectivity: Vec<[usize; 8]>,
    /// Worst invariant margins over every car's fluid ([`FluidVehicle::margins`]).
    pub margins: Margins,
}

impl FluidTrainRecord {
    /// Column names of [`Self::row`]: the [`TrainRecord::columns`] followed, per car, by the
    /// oil centre of mass (tank frame), the fluid force on the tank (tank frame), the
    /// relative volume change and the invariants (containment gap, smallest volume ratio,
    /// energy growth).
    pub fn columns(wheelsets: usize, couplers: usize, cars: usize) -> Vec<String> {
        let mut c = TrainRecord::columns(wheelsets, couplers, cars);
        for k in 0..cars {
            c.extend(["x", "y", "z"].map(|a| format!("oil_com_tank[{k}].{a}")));
            c.extend(["x", "y", "z"].map(|a| format!("fluid_force_tank[{k}].{a}")));
            c.push(format!("volume_error[{k}]"));
            c.extend(["containment_gap", "min_volume_ratio", "energy_error"].map(|n| format!("{n}[{k}]")));
        }
        c
    }

    /// The load channels of sample `i` ([`super::LoadFilter`]): those of
    /// [`TrainRecord::loads_into`], then the fluid force on each tank (tank frame).
    pub fn loads_into(&self, i: usize, out: &mut Vec<f64>) {
        self.train.loads_into(i, out);
        out.extend(self.fluid_force_tank[i].iter().flatten());
    }

    /// Replaces the load channels of sample `i` (layout of [`Self::loads_into`]).
    pub fn set_loads(&mut self, i: usize, loads: &[f64]) {
        let n = self.train.set_loads(i, loads);
        for (x, &l) in self.fluid_force_tank[i].iter_mut().flatten().zip(&loads[n.min(loads.len())..]) {
            *x = l;
        }
    }

    fn clear_samples(&mut self) {
        self.train.clear_samples();
        self.oil_com_tank.clear();
        self.oil_com_global.clear();
        self.fluid_force_tank.clear();
        self.volume_error.clear();
        self.containment_gap.clear();
        self.min_volume_ratio.clear();
        self.energy_error.clear();
    }

    /// Sample `i` as one flat row in the order of [`Self::columns`].
    pub fn row(&self, i: usize) -> Vec<f64> {
        let mut r = self.train.row(i);
        for k in 0..self.oil_com_tank[i].len() {
            r.extend(self.oil_com_tank[i][k]);
            r.extend(self.fluid_force_tank[i][k]);
            r.push(self.volume_error[i][k]);
            r.extend([self.containment_gap[i][k], self.min_volume_ratio[i][k], self.energy_error[i][k]]);
        }
        r
    }
}

/// A fluid run that stopped early: why, and what was recorded.
pub type FluidTrainFailure = RunFailure<FluidTrainRecord>;

/// Builds a train whose tanks carry `cargo` as ANCF fluid bodies.
pub fn build_fluid_train(
    sc: &TrainScenario,
    cargo: &FluidCargo,
) -> Result<(FluidVehicle, Vec<CarBodies>, Vec<usize>), AncfError> {
    let p = &sc.car;
    let spec = p.tank_spec(cargo.fill, cargo.counts);
    let mesh = if cargo.bulkheads.is_empty() {
        cylinder_tank(&spec)?
    } else {
        cylinder_tank_compartments(&spec, &cargo.bulkheads)?
    };
    let depth = 2.0 * p.tank_radius * cargo.fill;
    let mut fluid = cargo.fluid;
    if cargo.shear_stabilization && fluid.shear_stabilization == 0.0 {
        let element_height = depth / cargo.counts[2].max(1) as f64;
        let heads = (spec.head_depth > 0.0).then_some(depth);
        fluid.shear_stabilization = crate::defaults::default_shear_stabilization(fluid.density, element_height, heads);
    }
    let body = FluidBody::new(mesh, fluid, cargo.quadrature)?;
    let geometry = TankGeometry::new(
        spec.shape(),
        cargo.bulkheads.iter().map(|&(x, thickness)| Bulkhead { x, thickness }).collect(),
    )?;
    let g = crate::track::GRAVITY;
    let rho = cargo.fluid.density;
    let mut law = WallContactLaw::default_for(rho, g, depth)
        .with_damping_ratio(cargo.wall_damping_ratio, rho, g, depth)?
        .with_adhesion(cargo.wall_adhesion, rho, g, depth)?;
    ancf_core::error::check_positive("wall_stiffness_factor", cargo.wall_stiffness_factor)?;
    law.stiffness *= cargo.wall_stiffness_factor;
    law.damping *= cargo.wall_stiffness_factor.powf(1.5);
    law.points_per_edge = cargo.contact_points_per_edge;
    let contact = WallContact::new(&body, geometry, law)?;
    let mut sc2 = sc.clone();
    sc2.car.carried_mass = body.total_mass();
    sc2.car.lading = None;
    let (mb, cars, couplers) = build_train(&sc2)?;
    let fluids =
        cars.iter().map(|c| TankFluid { tank: c.tank, body: body.clone(), contact: contact.clone() }).collect();
    let mut vehicle = FluidVehicle::new(mb, fluids)?;
    vehicle.linear_solver = cargo.linear_solver;
    Ok((vehicle, cars, couplers))
}

fn record_fluid(sys: &FluidVehicle, q: &[f64], v: &[f64], rec: &mut FluidTrainRecord) {
    let nr = sys.mb.n_coords();
    let mut com = Vec::new();
    let mut com_g = Vec::new();
    let mut load = Vec::new();
    let mut vol = Vec::new();
    let (mut gap, mut ratio, mut eps) = (Vec::new(), Vec::new(), Vec::new());
    for (k, f) in sys.fluids.iter().enumerate() {
        let s = sys.mb.state(Some(f.tank), &q[..nr], &v[..nr]);
        let e = sys.fluid_slice(k, q);
        let (g, j, eps_k) = match sys.monitors[k].last_measured() {
            Some(m) => (m.gap, m.min_volume_ratio, m.energy_error),
            // the initial state, before any step: measured here; the energy account starts at
            // the first accepted step, so its growth is 0 by definition
            None => {
                let monitor = &sys.monitors[k];
                let kin = tank_kinematics(&s);
                let (g, j) = check_state(|| monitor.name.clone(), &f.body, &f.contact, &kin, e, &monitor.limits)
                    .unwrap_or_else(|(_, g, j)| (g, j));
                (g, j, 0.0)
            }
        };
        gap.push(g);
        ratio.push(j);
        eps.push(eps_k);
        let c = Vector3::from(f.body.center_of_mass(e));
        com.push(<[f64; 3]>::from(s.rotation.transpose() * (c - s.position)));
        com_g.push(<[f64; 3]>::from(c));
        let l = sys.fluid_load(k, q, v);
        load.push(<[f64; 3]>::from(s.rotation.transpose() * Vector3::from(l.force)));
        vol.push(f.body.volume(e) / f.body.reference_volume() - 1.0);
    }
    rec.oil_com_tank.push(com);
    rec.oil_com_global.push(com_g);
    rec.fluid_force_tank.push(load);
    rec.volume_error.push(vol);
    rec.containment_gap.push(gap);
    rec.min_volume_ratio.push(ratio);
    rec.energy_error.push(eps);
}

/// [`run_vehicle`](crate::vehicle::run_vehicle) of an ANCF fluid cargo, without observer or stream.
pub fn run_fluid_train(sc: &TrainScenario, cargo: &FluidCargo) -> RunResult<FluidTrainRecord> {
    run_vehicle(sc, cargo, &mut |_| true, None)
}

impl Cargo for FluidCargo {
    type Record = FluidTrainRecord;
    fn columns(&self, sc: &TrainScenario) -> Result<Vec<String>, AncfError> {
        Ok(FluidTrainRecord::columns(4 * sc.cars, sc.cars.saturating_sub(1), sc.cars))
    }
    fn run(
        &self,
        sc: &TrainScenario,
        observe: Observer<'_>,
        sink: Option<SampleSink<'_>>,
    ) -> RunResult<FluidTrainRecord> {
        run_fluid(sc, self, observe, sink)
    }
}

fn run_fluid(
    sc: &TrainScenario,
    cargo: &FluidCargo,
    observe: Observer<'_>,
    sink: Option<SampleSink<'_>>,
) -> RunResult<FluidTrainRecord> {
    let (sys, cars, couplers) = build_fluid_train(sc, cargo)?;
    let mut rec = FluidTrainRecord {
        fluid_mass: sys.fluids[0].body.total_mass(),
        elements: sys.fluids[0].body.mesh.n_elements(),
        connectivity: sys.fluids[0].body.mesh.elements.clone(),
        ..Default::default()
    };
    rec.train.static_wheel_load = cars[0].static_wheel_load;
    rec.train.dof = sys.mb.dof() + sys.fluids.iter().map(|f| f.body.n_coords() as isize).sum::<isize>();
    let init = sys.initial_coordinates();
    let hints = cars.iter().flat_map(|c| [c.station; 4]).collect();
    let run = FluidRun { sc, nr: sys.mb.n_coords(), cars, couplers, hints };
    Ok(drive(run, sys, init, sc, observe, sink, rec))
}

/// The ANCF-fluid run ([`run_fluid_train`]): the vehicle channels, each fluid's, and snapshots.
struct FluidRun<'a> {
    sc: &'a TrainScenario,
    /// Rigid coordinates (the fluids follow).
    nr: usize,
    cars: Vec<CarBodies>,
    couplers: Vec<usize>,
    /// Warm starts of the wheel/rail search at the recorded samples.
    hints: Vec<f64>,
}

impl TrainRun for FluidRun<'_> {
    type System = FluidVehicle;
    type Record = FluidTrainRecord;
    fn train(rec: &mut FluidTrainRecord) -> &mut TrainRecord {
        &mut rec.train
    }
    fn sample(
        &mut self,
        hht: &mut Hht<FluidVehicle>,
        k: usize,
        rec: &mut FluidTrainRecord,
        full: bool,
    ) -> Result<(), IntegratorError> {
        let (t, q, v) = (hht.t(), hht.q().to_vec(), hht.v().to_vec());
        let a = hht.a()[..self.nr].to_vec();
        let (nr, sc) = (self.nr, self.sc);
        let sys = hht.system_observed();
        let state = (t, &q[..nr], &v[..nr], &a[..]);
        record_sample(&mut sys.mb, state, &sc.track, &self.cars, &self.couplers, &mut self.hints, &mut rec.train)?;
        record_fluid(hht.system(), &q, &v, rec);
        if full && sc.snapshot_every > 0.0 {
            let every = (sc.snapshot_every / sc.record_every).round().max(1.0) as usize;
            if k.is_multiple_of(every) {
                let sys = hht.system();
                let e = (0..sys.fluids.len()).map(|f| sys.fluid_slice(f, &q).to_vec()).collect();
                rec.snapshots.push((t, e));
            }
        }
        Ok(())
    }
    fn clear_samples(rec: &mut FluidTrainRecord) {
        rec.clear_samples();
    }
    fn loads_into(rec: &FluidTrainRecord, i: usize, out: &mut Vec<f64>) {
        rec.loads_into(i, out);
    }
    fn set_loads(rec: &mut FluidTrainRecord, i: usize, loads: &[f64]) {
        rec.set_loads(i, loads);
    }
    fn row(rec: &FluidTrainRecord, i: usize) -> Vec<f64> {
        rec.row(i)
    }
    fn hints(&mut self) -> &mut Vec<f64> {
        &mut self.hints
    }
    fn finish(hht: &Hht<FluidVehicle>, rec: &mut FluidTrainRecord) {
        rec.margins = hht.system().margins();
    }
}
