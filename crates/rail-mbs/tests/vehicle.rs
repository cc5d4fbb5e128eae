//! Vehicle model: DOF count, a two-car train whose braked front car compresses the coupler,
//! and bad input (the `static-wheel-loads` case runs in `railslosh-cases`' `vehicle_cases`).

use std::sync::Arc;

use rail_mbs::mbs::Table;
use rail_mbs::track::Track;
use rail_mbs::vehicle::{BrakeScope, TankCarParams, TrainScenario, TruckModel, build_train, run_train};

fn tangent() -> Arc<Track> {
    Arc::new(Track::straight(3000.0).unwrap())
}

/// One tank car: the slosh cases' and Python's `CylinderTankSpec::tank_car` is the vehicle runs'
/// tank (12 m overall with its heads, so an 11 m shell; until 2026-11-26 the slosh side had a
/// 12 m shell, a tank 1 m longer than the vehicle's).
#[test]
fn the_slosh_tank_car_is_the_vehicle_runs_tank() {
    let car = TankCarParams::standard().unwrap();
    for counts in [[2, 2, 2], [6, 4, 2]] {
        assert_eq!(car.tank_spec(0.5, counts), ancf_core::mesh::CylinderTankSpec::tank_car(counts));
    }
    let spec = ancf_core::mesh::CylinderTankSpec::tank_car([6, 4, 2]);
    assert_eq!(spec.length + 2.0 * spec.head_depth, car.tank_length);
    assert_eq!((car.tank_length, car.tank_radius), (12.0, 1.5));
}

#[test]
fn tank_car_and_train_have_the_documented_structure() {
    let sc = TrainScenario::single(TankCarParams::standard().unwrap(), tangent(), 100.0, 0.0, 1.0);
    let (mb, cars, couplers) = build_train(&sc).unwrap();
    assert_eq!(mb.bodies().len(), 15);
    assert_eq!(mb.dof(), 68);
    assert!(couplers.is_empty());
    assert_eq!(cars[0].wheelsets.len(), 4);
    let mut two = sc.clone();
    two.cars = 2;
    let (mb, _, couplers) = build_train(&two).unwrap();
    assert_eq!(mb.dof(), 136);
    assert_eq!(couplers.len(), 1);
    // A three-piece truck: two side frames (6 DOF each) instead of one frame on its pin (1 DOF
    // beyond the bolster), and the bolster in the centre bowl (1 DOF) instead of on springs (6).
    let mut three = sc.clone();
    three.car.truck = TruckModel::ThreePiece;
    let (mb, cars, _) = build_train(&three).unwrap();
    assert_eq!(mb.bodies().len(), 17);
    assert_eq!(mb.dof(), 68 + 2 * (12 + 1 - 1 - 6));
    let [left, right] = cars[0].frames[0];
    assert_ne!(left, right);
    assert_eq!(mb.bodies()[left.0].name, "car1/bogie1/side_frameL");
    assert_eq!(TruckModel::from_name("three_piece").unwrap().name(), "three_piece");
    assert!(TruckModel::from_name("bogie").unwrap_err().to_string().contains("truck"));
}

#[test]
fn braking_the_front_car_compresses_the_coupler() {
    let v = 20.0 / 3.6;
    let mut sc = TrainScenario::single(TankCarParams::standard().unwrap(), tangent(), 100.0, v, 0.6);
    sc.cars = 2;
    sc.record_every = 0.05;
    let torque = Table::new("brake", vec![0.0, 0.1], vec![0.0, 6000.0]).unwrap();
    sc.brake = Some((torque, BrakeScope::FrontCar));
    let rec = run_train(&sc).unwrap().unwrap();
    let f: Vec<f64> = rec.coupler_force.iter().map(|c| c[0]).collect();
    println!("coupler force {f:?}");
    let late = &f[f.len() / 2..];
    assert!(late.iter().all(|&x| x < 0.0), "coupler should be in compression: {late:?}");
    // Both cars decelerate.
    let s = &rec.tank_speed;
    assert!(s.last().unwrap()[0] < v && s.last().unwrap()[1] < v);
}

#[test]
fn bad_scenario_input_names_the_field() {
    let mut sc = TrainScenario::single(TankCarParams::standard().unwrap(), tangent(), 100.0, 0.0, 1.0);
    sc.cars = 0;
    let e = build_train(&sc).unwrap_err().to_string();
    assert!(e.contains("cars"), "{e}");
    let mut p = TankCarParams::standard().unwrap();
    p.wheelbase = 20.0;
    let sc = TrainScenario::single(p, tangent(), 100.0, 0.0, 1.0);
    let e = build_train(&sc).unwrap_err().to_string();
    assert!(e.contains("wheelbase"), "{e}");
}

#[test]
fn coupler_faces_stay_at_the_coupler_height_with_rigid_lading_off_the_axis() {
    // Rigid lading below the tank axis moves the tank body's centre of mass (its frame origin)
    // down; the coupler must stay at `coupler_height` above the rail (regression: it moved
    // down with the centre of mass). The face height is read from the coupler's wrench on the
    // front tank after pulling the rear car back: arm_z = M_y / F_x.
    for lading in [None, Some((40_000.0, -0.6)), Some((20_000.0, 0.4))] {
        let mut p = TankCarParams::standard().unwrap();
        p.lading = lading;
        let mut sc = TrainScenario::single(p.clone(), tangent(), 100.0, 0.0, 1.0);
        sc.cars = 2;
        let (mb, cars, couplers) = build_train(&sc).unwrap();
        let coupler = &mb.forces()[couplers[0]];
        let front = mb.initial_state(Some(cars[0].tank));
        let mut rear = mb.initial_state(Some(cars[1].tank));
        rear.position.x -= 1e-3; // pull apart: tension
        let [wf, _] = coupler.wrenches(0.0, &front, &rear);
        assert!(wf.force.x.abs() > 1e3, "{:?}", wf.force);
        let arm_z = wf.moment.y / wf.force.x;
        let face_height = front.position.z + arm_z;
        assert!(
            (face_height - p.coupler_height).abs() < 1e-6,
            "lading {lading:?}: coupler face at {face_height} m, expected {} m",
            p.coupler_height
        );
    }
}

#[test]
fn the_recorded_car_acceleration_is_the_derivative_of_the_car_speed() {
    // A braked single car on tangent track: its longitudinal car-body acceleration (a load
    // channel, hat-mean filtered) equals d(speed)/dt from the recorded speeds, the lateral one
    // stays zero, and the vertical one is zero on average (the car neither rises nor sinks).
    let v = 30.0 / 3.6;
    let mut sc = TrainScenario::single(TankCarParams::standard().unwrap(), tangent(), 100.0, v, 2.0);
    sc.record_every = 0.01;
    let torque = Table::new("brake", vec![0.0, 0.3, 2.0], vec![0.0, 8000.0, 8000.0]).unwrap();
    sc.brake = Some((torque, BrakeScope::AllCars));
    let rec = run_train(&sc).unwrap().unwrap();
    let n = rec.t.len();
    assert_eq!(rec.car_acceleration.len(), n);
    let mut worst: f64 = 0.0;
    let mut decel_seen: f64 = 0.0;
    for i in (n / 2)..n - 1 {
        let dvdt = (rec.tank_speed[i + 1][0] - rec.tank_speed[i - 1][0]) / (rec.t[i + 1] - rec.t[i - 1]);
        let ax = rec.car_acceleration[i][0][0];
        worst = worst.max((ax - dvdt).abs());
        decel_seen = decel_seen.min(ax);
        assert!(rec.car_acceleration[i][0][1].abs() < 1e-6, "lateral {:?}", rec.car_acceleration[i]);
    }
    let mean_z: f64 = rec.car_acceleration[n / 2..].iter().map(|a| a[0][2]).sum::<f64>() / (n - n / 2) as f64;
    println!(
        "braking: car acceleration x down to {decel_seen:.4} m/s², |a_x − dv/dt| ≤ {worst:.2e}, mean a_z {mean_z:.2e}"
    );
    assert!(decel_seen < -0.1, "the brake decelerates the car: {decel_seen}");
    assert!(worst < 0.02 * decel_seen.abs(), "{worst} vs {decel_seen}");
    assert!(mean_z.abs() < 1e-3, "{mean_z}");
}

#[test]
fn rigid_lading_spread_over_a_length_carries_its_rod_inertia_in_pitch_and_yaw() {
    let (m, h, l) = (60_000.0, -0.3, 11.7);
    let inertia = |length: f64| {
        let mut p = TankCarParams::standard().unwrap();
        p.lading = Some((m, h));
        p.lading_length = length;
        let sc = TrainScenario::single(p, tangent(), 100.0, 0.0, 1.0);
        let (mb, cars, _) = build_train(&sc).unwrap();
        mb.bodies()[cars[0].tank.0].inertia
    };
    let (point, spread) = (inertia(0.0), inertia(l));
    let rod = m * l * l / 12.0;
    assert!((spread[(0, 0)] - point[(0, 0)]).abs() < 1e-6, "roll unchanged");
    assert!((spread[(1, 1)] - point[(1, 1)] - rod).abs() < 1e-6 * rod, "pitch + m L²/12");
    assert!((spread[(2, 2)] - point[(2, 2)] - rod).abs() < 1e-6 * rod, "yaw + m L²/12");
    let mut p = TankCarParams::standard().unwrap();
    p.lading_length = -1.0;
    let e = p.validate().unwrap_err().to_string();
    assert!(e.contains("`lading_length` = -1"), "{e}");
}
