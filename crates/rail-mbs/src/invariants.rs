//! Run-time invariants of a fluid run (issue 16): checked after every accepted step of
//! every run kind that carries ANCF liquid, so that a run which exits normally is
//! physically valid.
//!
//! | invariant | measured | error |
//! |---|---|---|
//! | containment | the largest wall gap ψ of every fluid node, every contact point and the centre of mass ([`WallContact::containment`]) | [`SystemError::Containment`] beyond [`InvariantLimits::containment`] |
//! | element validity | the smallest volume ratio J = det F over every quadrature point of the viscous, penalty and mass rules and the 3×3×3 Gauss–Lobatto check points of each element ([`FluidBody::volume_ratio_range`]) | [`SystemError::InvertedElement`] at J ≤ 0, [`SystemError::DistortedElement`] at J ≤ [`InvariantLimits::min_volume_ratio`] |
//! | energy balance | ε = (E − E₀ − W_in) / E_ref with E = kinetic + gravitational + penalty + contact-spring energy and W_in the work the moving walls do on the liquid | [`SystemError::EnergyGrowth`] when ε > [`InvariantLimits::energy`] |
//!
//! The energy balance is the one explicit-dynamics codes report. With D ≥ 0 the energy
//! dissipated (viscous and bulk viscosity, contact damping, and the integrator's own
//! numerical damping), E(t) = E₀ + W_in(t) − D(t), so ε = −D/E_ref ≤ 0 for any physical
//! run: growth means that something created energy (an unstable discretization, a bad
//! step). The dissipated energy is reported as D = E₀ + W_in − E. In the inertial
//! formulation the input is the wall work
//! W_in = −∫ (F·Ṙ + M·ω) dt with F, M the load of the liquid on the tank (global, moment
//! about the tank origin R) and Ṙ, ω the tank's velocities: the power of the wall
//! tractions on the liquid. It is integrated with the trapezoidal rule over the accepted
//! steps. In the tank-frame formulation E is the energy relative to the tank (kinetic,
//! penalty, contact) and W_in the work of gravity and of the pseudo-forces
//! −ρ[a + ω̇ × r + ω × (ω × r)] (the Coriolis force does no work). The reference
//! E_ref = m g H + max KE + ∫|P_in| dt (H the liquid depth) keeps ε meaningful both for a
//! liquid at rest and under a manoeuvre that pumps energy in and out.

use ancf_core::FluidBody;
use ancf_core::contact::{TankKinematics, WallContact};

use crate::integrator::SystemError;

/// Limits of the run-time invariants.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InvariantLimits {
    /// Largest admissible gap ψ beyond a wall of any fluid node, contact point or of the
    /// centre of mass (m).
    pub containment: f64,
    /// Largest admissible energy growth ε (relative to E_ref, see the module docs).
    pub energy: f64,
    /// Smallest admissible volume ratio J = det F at any quadrature point (> 0).
    pub min_volume_ratio: f64,
}

/// Default energy-growth limit: 5 % of the run's energy scale. The implicit integrator
/// dissipates (ε ≤ 0); the trapezoidal wall work adds an O(h²) error: the largest ε over
/// every shipped scene was 7.9e-5 (docs/validation.md).
pub const ENERGY_GROWTH_LIMIT: f64 = 0.05;

/// Default smallest volume ratio: an element compressed to a tenth of its volume at any
/// quadrature point is no longer a liquid element (the penalty holds |J − 1| ≈ 10⁻³).
pub const MIN_VOLUME_RATIO: f64 = 0.1;

impl InvariantLimits {
    /// Defaults: containment within `containment` (m; the runs pass their penetration
    /// limit, half the smallest element edge), [`ENERGY_GROWTH_LIMIT`], [`MIN_VOLUME_RATIO`].
    pub fn new(containment: f64) -> Self {
        Self { containment, energy: ENERGY_GROWTH_LIMIT, min_volume_ratio: MIN_VOLUME_RATIO }
    }
}

/// Worst margins of a run so far (reported in results and `run.json`).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Margins {
    /// Largest wall gap of any node, contact point or the centre of mass (m, ≥ 0).
    pub worst_gap: f64,
    /// Time of `worst_gap` (s).
    pub worst_gap_time: f64,
    /// The admissible gap (m): [`InvariantLimits::containment`] (the smallest over the
    /// liquids of a vehicle).
    pub gap_limit: f64,
    /// Largest energy growth ε (≤ 0 for a dissipative run).
    pub worst_energy_error: f64,
    /// Time of `worst_energy_error` (s).
    pub worst_energy_time: f64,
    /// Smallest volume ratio J at any quadrature point.
    pub min_volume_ratio: f64,
    /// Time of `min_volume_ratio` (s).
    pub min_volume_ratio_time: f64,
    /// Energy dissipated so far, D = E₀ + W_in − E (J).
    pub dissipated: f64,
}

impl Margins {
    /// The fields in declaration order (a run checkpoint, [`Self::from_array`]).
    fn to_array(self) -> [f64; 8] {
        [
            self.worst_gap,
            self.worst_gap_time,
            self.gap_limit,
            self.worst_energy_error,
            self.worst_energy_time,
            self.min_volume_ratio,
            self.min_volume_ratio_time,
            self.dissipated,
        ]
    }

    /// [`Self::to_array`] read back.
    fn from_array(a: [f64; 8]) -> Self {
        let [
            worst_gap,
            worst_gap_time,
            gap_limit,
            worst_energy_error,
            worst_energy_time,
            min_volume_ratio,
            min_volume_ratio_time,
            dissipated,
        ] = a;
        Self {
            worst_gap,
            worst_gap_time,
            gap_limit,
            worst_energy_error,
            worst_energy_time,
            min_volume_ratio,
            min_volume_ratio_time,
            dissipated,
        }
    }

    /// Keeps the worst of a state's gap and smallest volume ratio (time `t`).
    pub fn note(&mut self, t: f64, gap: f64, j: f64) {
        if gap > self.worst_gap {
            self.worst_gap = gap;
            self.worst_gap_time = t;
        }
        if j.is_nan() || j < self.min_volume_ratio {
            self.min_volume_ratio = j;
            self.min_volume_ratio_time = t;
        }
    }

    /// The worse of two margins (energy figures from whichever has the larger growth).
    pub fn worst(self, other: Self) -> Self {
        let mut m = self;
        m.note(other.worst_gap_time, other.worst_gap, f64::INFINITY);
        m.note(other.min_volume_ratio_time, 0.0, other.min_volume_ratio);
        if other.worst_energy_error > m.worst_energy_error {
            (m.worst_energy_error, m.worst_energy_time) = (other.worst_energy_error, other.worst_energy_time);
        }
        m.dissipated = self.dissipated + other.dissipated;
        m.gap_limit = self.gap_limit.min(other.gap_limit);
        m
    }
}

impl Default for Margins {
    fn default() -> Self {
        Self {
            worst_gap: 0.0,
            worst_gap_time: 0.0,
            gap_limit: f64::INFINITY,
            worst_energy_error: f64::NEG_INFINITY,
            worst_energy_time: 0.0,
            min_volume_ratio: f64::INFINITY,
            min_volume_ratio_time: 0.0,
            dissipated: 0.0,
        }
    }
}

/// What [`InvariantMonitor::check`] measured on one accepted state.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Measured {
    /// Largest wall gap of any node, contact point or the centre of mass (m, ≥ 0).
    pub gap: f64,
    /// Smallest volume ratio J at any quadrature point.
    pub min_volume_ratio: f64,
    /// Energy growth ε.
    pub energy_error: f64,
    /// Work put into the liquid so far, ∫ input power dt (J).
    pub input_work: f64,
}

/// A state that passed [`InvariantMonitor::assess`], to be accounted by
/// [`InvariantMonitor::commit`] once its step is accepted.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Pending {
    t: f64,
    gap: f64,
    j: f64,
    work: f64,
    abs_work: f64,
    max_kinetic: f64,
    total: f64,
    power: f64,
    eps: f64,
}

/// One accepted state of one liquid, as the monitor needs it.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct EnergySample {
    /// Kinetic energy (J, inertial velocities).
    pub kinetic: f64,
    /// Gravitational potential energy (J).
    pub potential: f64,
    /// Stored elastic energy: volumetric penalty + contact springs (J).
    pub stored: f64,
    /// Power put into the liquid from outside its energy E (W): the wall tractions in
    /// the inertial formulation ([`wall_power`]); gravity and the pseudo-forces in the
    /// tank-frame formulation, where E holds no gravitational term.
    pub input_power: f64,
}

impl EnergySample {
    /// Kinetic + potential + stored.
    pub fn total(&self) -> f64 {
        self.kinetic + self.potential + self.stored
    }
}

/// Power of the walls on the liquid, −(F·Ṙ + M·ω), from the liquid's load on the tank
/// (force F, moment M about the tank origin, global) and the tank's velocities.
pub fn wall_power(force: [f64; 3], moment: [f64; 3], kin: &TankKinematics) -> f64 {
    -(0..3).map(|i| force[i] * kin.velocity[i] + moment[i] * kin.angular_velocity[i]).sum::<f64>()
}

/// Stored elastic energy of one liquid: penalty + contact springs (J).
pub fn stored_energy(body: &FluidBody, contact: &WallContact, kin: &TankKinematics, q: &[f64]) -> f64 {
    body.penalty_energy(q) + body.stabilization_energy(q) + contact.stored_energy(body, kin, q)
}

/// The state invariants of one liquid (`what()` names it in errors; called only then): containment within
/// `limits.containment` and element validity. Returns the largest wall gap and the
/// smallest volume ratio; on a violation, the error with the same two figures.
#[allow(clippy::type_complexity)]
pub fn check_state(
    what: impl Fn() -> String,
    body: &FluidBody,
    contact: &WallContact,
    kin: &TankKinematics,
    q: &[f64],
    limits: &InvariantLimits,
) -> Result<(f64, f64), (SystemError, f64, f64)> {
    let breach = contact.containment(body, kin, q);
    let gap = breach.map_or(0.0, |b| b.depth);
    let j = body.volume_ratio_range(q);
    if let Some(b) = breach
        && b.depth > limits.containment
    {
        let e = SystemError::Containment {
            what: what(),
            site: b.site.to_string(),
            position: b.position,
            depth: b.depth,
            limit: limits.containment,
        };
        return Err((e, gap, j.min));
    }
    if j.min.is_nan() || j.min <= 0.0 {
        return Err((SystemError::InvertedElement { element: j.element, point: j.point, j: j.min }, gap, j.min));
    }
    if j.min <= limits.min_volume_ratio {
        let e = SystemError::DistortedElement {
            element: j.element,
            point: j.point,
            j: j.min,
            limit: limits.min_volume_ratio,
        };
        return Err((e, gap, j.min));
    }
    Ok((gap, j.min))
}

/// Checks the invariants of one liquid after each accepted step and keeps the energy
/// account and the worst margins.
#[derive(Debug, Clone)]
pub struct InvariantMonitor {
    /// Limits.
    pub limits: InvariantLimits,
    /// Name of the liquid in errors (e.g. "fluid", "car 1 fluid").
    pub name: String,
    /// m g H of the liquid (J), the floor of E_ref.
    energy_floor: f64,
    e0: Option<f64>,
    last: Option<(f64, f64)>,
    input_work: f64,
    abs_work: f64,
    max_kinetic: f64,
    margins: Margins,
    last_measured: Option<Measured>,
}

impl InvariantMonitor {
    /// A monitor for a liquid of mass `mass` and depth `depth` under gravity `g`.
    pub fn new(name: impl Into<String>, limits: InvariantLimits, mass: f64, g: f64, depth: f64) -> Self {
        Self {
            limits,
            name: name.into(),
            energy_floor: (mass * g * depth).abs().max(f64::MIN_POSITIVE),
            e0: None,
            last: None,
            input_work: 0.0,
            abs_work: 0.0,
            max_kinetic: 0.0,
            margins: Margins { gap_limit: limits.containment, ..Margins::default() },
            last_measured: None,
        }
    }

    /// Appends the monitor's account (energy reference, work so far, worst margins, the last
    /// state's measures) to `out`, as [`Self::restore_account`] reads it back: a resumed run
    /// goes on with the same energy balance and margins.
    pub fn save_account(&self, out: &mut Vec<f64>) {
        let opt = |x: Option<f64>| [x.map_or(0.0, |_| 1.0), x.unwrap_or(0.0)];
        out.extend(opt(self.e0));
        out.extend(opt(self.last.map(|l| l.0)));
        out.push(self.last.map_or(0.0, |l| l.1));
        out.extend([self.input_work, self.abs_work, self.max_kinetic]);
        out.extend(self.margins.to_array());
        let l = self.last_measured;
        out.push(l.map_or(0.0, |_| 1.0));
        let l = l.unwrap_or(Measured { gap: 0.0, min_volume_ratio: 0.0, energy_error: 0.0, input_work: 0.0 });
        out.extend([l.gap, l.min_volume_ratio, l.energy_error, l.input_work]);
    }

    /// Reads an account written by [`Self::save_account`] from the front of `data`, advancing
    /// it; `None` when `data` is too short.
    pub fn restore_account(&mut self, data: &mut &[f64]) -> Option<()> {
        const LEN: usize = 2 + 3 + 3 + 8 + 1 + 4;
        let d = data.get(..LEN)?;
        let opt = |flag: f64, x: f64| (flag == 1.0).then_some(x);
        self.e0 = opt(d[0], d[1]);
        self.last = opt(d[2], d[3]).map(|t| (t, d[4]));
        [self.input_work, self.abs_work, self.max_kinetic] = [d[5], d[6], d[7]];
        self.margins = Margins::from_array(d[8..16].try_into().expect("8 values"));
        self.last_measured = (d[16] == 1.0).then_some(Measured {
            gap: d[17],
            min_volume_ratio: d[18],
            energy_error: d[19],
            input_work: d[20],
        });
        *data = &data[LEN..];
        Some(())
    }

    /// [`Self::restore_account`] of exactly one account: `None` when `data` is shorter or
    /// longer (an account of another run).
    pub fn restore_whole_account(&mut self, mut data: &[f64]) -> Option<()> {
        self.restore_account(&mut data)?;
        data.is_empty().then_some(())
    }

    /// What the last accounted state measured (None before the first).
    pub fn last_measured(&self) -> Option<Measured> {
        self.last_measured
    }

    /// The worst margins so far.
    pub fn margins(&self) -> Margins {
        self.margins
    }

    /// Starts a new energy account from the next state checked (its energy becomes E₀, no
    /// work before it), keeping the margins: for a run whose input was reset (a new initial
    /// input, a settled state with its clock set back, a restored state).
    pub fn restart_energy(&mut self) {
        (self.e0, self.last, self.input_work, self.abs_work, self.max_kinetic) = (None, None, 0.0, 0.0, 0.0);
    }

    /// Work put into the liquid so far (J).
    pub fn input_work(&self) -> f64 {
        self.input_work
    }

    /// The energy growth ε of a sample (updates nothing).
    fn energy_error(&self, total: f64, input_work: f64, max_kinetic: f64, abs_work: f64) -> f64 {
        let e0 = self.e0.unwrap_or(total);
        (total - e0 - input_work) / (self.energy_floor + max_kinetic + abs_work)
    }

    /// Account one accepted state at time `t` and check every invariant: containment
    /// ([`WallContact::containment`]), element validity (`body`, `q`) and the energy
    /// balance. The first call sets E₀. On a violation the worst gap and volume ratio are
    /// kept (they describe the violating state) and nothing else is accounted.
    pub fn check(
        &mut self,
        t: f64,
        body: &FluidBody,
        contact: &WallContact,
        kin: &TankKinematics,
        q: &[f64],
        energy: EnergySample,
    ) -> Result<Measured, SystemError> {
        let assessed = self.assess(t, body, contact, kin, q, energy);
        self.account(t, assessed)
    }

    /// [`Self::check`] with the state already measured (see [`Self::assess_energy`]).
    pub fn check_energy(
        &mut self,
        t: f64,
        measured: (f64, f64),
        energy: EnergySample,
    ) -> Result<Measured, SystemError> {
        let assessed = self.assess_energy(t, measured, energy);
        self.account(t, assessed)
    }

    /// Commits an assessed state, or notes the violating one's margins and returns its error.
    fn account(&mut self, t: f64, assessed: Result<Pending, (SystemError, f64, f64)>) -> Result<Measured, SystemError> {
        match assessed {
            Ok(p) => Ok(self.commit(p)),
            Err((e, gap, j)) => {
                self.note(t, gap, j);
                Err(e)
            }
        }
    }

    /// Checks every invariant of a state without accounting it (for systems with several
    /// liquids, where a step is accepted only when every liquid passes): the result is
    /// given to [`Self::commit`] once the step is accepted. On a violation, the error with
    /// the state's largest gap and smallest volume ratio.
    #[allow(clippy::type_complexity)]
    pub fn assess(
        &self,
        t: f64,
        body: &FluidBody,
        contact: &WallContact,
        kin: &TankKinematics,
        q: &[f64],
        energy: EnergySample,
    ) -> Result<Pending, (SystemError, f64, f64)> {
        let measured = check_state(|| self.name.clone(), body, contact, kin, q, &self.limits)?;
        self.assess_energy(t, measured, energy)
    }

    /// [`Self::assess`] of a state whose containment gap and smallest volume ratio
    /// `(gap, j)` were already measured by [`check_state`] with this monitor's limits (the
    /// slosh system's step check): the energy balance only.
    pub fn assess_energy(
        &self,
        t: f64,
        (gap, j): (f64, f64),
        energy: EnergySample,
    ) -> Result<Pending, (SystemError, f64, f64)> {
        // energy: trapezoidal work over the step since the last accepted state
        let (mut work, mut abs_work) = (self.input_work, self.abs_work);
        if let Some((t_last, p_last)) = self.last {
            work += 0.5 * (t - t_last) * (p_last + energy.input_power);
            abs_work += 0.5 * (t - t_last) * (p_last.abs() + energy.input_power.abs());
        }
        let total = energy.total();
        let max_kinetic = self.max_kinetic.max(energy.kinetic);
        let eps = self.energy_error(total, work, max_kinetic, abs_work);
        if eps.is_nan() || eps > self.limits.energy {
            let e = SystemError::EnergyGrowth {
                what: self.name.clone(),
                energy: total,
                initial: self.e0.unwrap_or(total),
                input_work: work,
                relative: eps,
                limit: self.limits.energy,
            };
            return Err((e, gap, j));
        }
        Ok(Pending { t, gap, j, work, abs_work, max_kinetic, total, power: energy.input_power, eps })
    }

    /// Accounts a state that [`Self::assess`] passed and that was accepted.
    pub fn commit(&mut self, p: Pending) -> Measured {
        self.note(p.t, p.gap, p.j);
        self.e0.get_or_insert(p.total);
        (self.input_work, self.abs_work, self.max_kinetic, self.last) =
            (p.work, p.abs_work, p.max_kinetic, Some((p.t, p.power)));
        let m = &mut self.margins;
        if p.eps > m.worst_energy_error {
            m.worst_energy_error = p.eps;
            m.worst_energy_time = p.t;
        }
        m.dissipated = self.e0.unwrap_or(p.total) + p.work - p.total;
        let measured = Measured { gap: p.gap, min_volume_ratio: p.j, energy_error: p.eps, input_work: p.work };
        self.last_measured = Some(measured);
        measured
    }

    /// Keeps the worst gap and volume ratio.
    fn note(&mut self, t: f64, gap: f64, j: f64) {
        self.margins.note(t, gap, j);
    }
}
