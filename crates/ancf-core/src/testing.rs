//! Test support shared by the tests, the benchmarks and the element validation cases (crate
//! `railslosh-cases`): sample fluids of every law and a finite-difference check of an
//! element's Jacobians. Library code does not use it; it is public so that the integration
//! tests and the cases crate run the same checks (issue 18 moved the cases out of the library
//! and left these here).

use crate::constitutive::{Fluid, Rheology};
use crate::element::{ElementRef, ShapeTables};
use crate::error::Result;
use crate::shape::N_COORDS;

/// The five rheologies with representative parameters, and a penalty; the sixth is the
/// Newtonian one with the shear stabilization ([`Fluid::shear_stabilization`]).
pub fn sample_fluids() -> Vec<Fluid> {
    let mk = |rheology| Fluid { bulk_damping: 20.0, ..Fluid::new(900.0, rheology, 2.0e5).expect("valid") };
    let newtonian = mk(Rheology::Newtonian { viscosity: 0.8 });
    vec![
        newtonian,
        mk(Rheology::Bingham { viscosity: 0.5, yield_stress: 3.0 }),
        mk(Rheology::HerschelBulkley { consistency: 0.7, power_index: 0.6, yield_stress: 2.0 }),
        mk(Rheology::Oldroyd { viscosity: 0.5, yield_stress: 40.0, elastic_modulus: Some(800.0) }),
        mk(Rheology::Casson { viscosity: 0.4, yield_stress: 2.5 }),
        Fluid { shear_stabilization: 300.0, ..newtonian },
    ]
}

/// The name of a sample fluid in records: its law, and "+ shear stabilization" when it has one.
pub fn sample_label(fluid: &Fluid) -> String {
    let name = fluid.rheology.name();
    if fluid.shear_stabilization > 0.0 { format!("{name} + shear stabilization") } else { name.to_string() }
}

/// Max relative finite-difference error of K = ∂f/∂e and C = ∂f/∂ė of one element.
pub fn jacobian_fd_error(
    fluid: &Fluid,
    el: &ElementRef,
    tables: &ShapeTables,
    e: &[f64],
    v: &[f64],
) -> Result<(f64, f64)> {
    let cpt = crate::element::to_compact;
    let mut f0 = [0.0; N_COORDS];
    let mut k = vec![0.0; N_COORDS * N_COORDS];
    let mut cm = vec![0.0; N_COORDS * N_COORDS];
    el.internal_force(0, fluid, tables, &cpt(e), &cpt(v), &mut f0, Some((&mut k, &mut cm)))?;
    let mut errs = [0.0f64; 2];
    for (w, jac) in [&k, &cm].into_iter().enumerate() {
        let scale = jac.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        let mut worst = 0.0f64;
        for d in 0..N_COORDS {
            let h = 1e-6;
            let (mut xp, mut xm) = if w == 0 { (e.to_vec(), e.to_vec()) } else { (v.to_vec(), v.to_vec()) };
            xp[d] += h;
            xm[d] -= h;
            let (mut fp, mut fm) = ([0.0; N_COORDS], [0.0; N_COORDS]);
            let (ep, em, vp, vm) = if w == 0 { (&xp[..], &xm[..], v, v) } else { (e, e, &xp[..], &xm[..]) };
            el.internal_force(0, fluid, tables, &cpt(ep), &cpt(vp), &mut fp, None)?;
            el.internal_force(0, fluid, tables, &cpt(em), &cpt(vm), &mut fm, None)?;
            for r in 0..N_COORDS {
                let fd = (fp[r] - fm[r]) / (2.0 * h);
                worst = worst.max((fd - jac[r * N_COORDS + d]).abs());
            }
        }
        errs[w] = worst / scale.max(1e-300);
    }
    Ok((errs[0], errs[1]))
}
