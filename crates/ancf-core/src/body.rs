//! A fluid body: a mesh with a fluid, its constant mass matrix, and batched evaluation
//! of the generalized forces.
//!
//! **Coordinate layout.** Node n carries r, r_x, r_y, r_z; global coordinate
//! `12 n + 3 m + i` is component i of vector m. The *scalar* index of (n, m) is `4 n + m`,
//! so the full mass matrix is M = M_s ⊗ I₃ with the 4N×4N scalar matrix M_s
//! ([`FluidBody::scalar_mass`]), as in Chrono's compact storage.
//!
//! **Batched kernel.** Every element shares one table of ∂n_a/∂ξ (see
//! [`crate::shape`]). For a chunk of elements the scaled coordinates and velocities are
//! stacked into a 32 × 6n_b matrix Ê, and one GEMM gives ∂r/∂ξ and ∂ṙ/∂ξ at every
//! quadrature point of every element; after the point-wise stress update a second GEMM
//! gives the forces. Chunks run in parallel (rayon) and are scattered in element order,
//! so results are bitwise identical for any thread count.

use faer::linalg::matmul::matmul;
use faer::sparse::{SparseColMat, Triplet};
use faer::{Accum, Mat, Par};
use nalgebra::Vector3;
use rayon::prelude::*;

use crate::constitutive::{Fluid, M3};
use crate::element::{Compact, ElementRef, QuadratureOptions, ShapeTables};
use crate::error::{AncfError, Result, check_len};
use crate::mesh::FluidMesh;
use crate::shape::{COORDS_PER_NODE, N_COORDS, N_SHAPE};

/// Elements per batched chunk.
const CHUNK: usize = 64;

/// Dense per-element Jacobians of the internal force.
#[derive(Debug, Clone)]
pub struct ElementJacobian {
    /// K = ∂f/∂e, row-major 96×96 in compact ordering `3a + i`.
    pub stiffness: Vec<f64>,
    /// C = ∂f/∂ė, row-major 96×96.
    pub damping: Vec<f64>,
}

/// A meshed fluid body with its precomputed reference data.
#[derive(Debug, Clone)]
pub struct FluidBody {
    /// The mesh (reference configuration).
    pub mesh: FluidMesh,
    /// The fluid.
    pub fluid: Fluid,
    /// Shape tables of the quadrature rules.
    pub tables: ShapeTables,
    /// Reference data per element.
    pub elements: Vec<ElementRef>,
    scalar_mass: SparseColMat<usize, f64>,
    gravity_scale: Vec<f64>,
    /// ∂n_a/∂ξ_J at all force points: row 3p + J, column a (viscous points, then penalty points).
    dn_t: Mat<f64>,
}

impl FluidBody {
    /// Build the body: validates the fluid and rules, precomputes reference data,
    /// assembles the scalar mass matrix and the gravity scale.
    pub fn new(mesh: FluidMesh, fluid: Fluid, quadrature: QuadratureOptions) -> Result<Self> {
        fluid.validate()?;
        let tables = ShapeTables::new(quadrature)?;
        let elements = mesh
            .elements
            .iter()
            .enumerate()
            .map(|(k, nodes)| {
                let e0 = gather_compact(&mesh.nodes, nodes);
                ElementRef::new(k, &e0, mesh.lengths[k], &tables)
            })
            .collect::<Result<Vec<_>>>()?;
        let ns = 4 * mesh.n_nodes();
        let mut trip = Vec::with_capacity(elements.len() * N_SHAPE * N_SHAPE);
        let mut gravity_scale = vec![0.0; ns];
        for (el, nodes) in elements.iter().zip(&mesh.elements) {
            let m = el.mass_compact(fluid.density, &tables);
            let g = el.gravity_scale(fluid.density, &tables);
            for a in 0..N_SHAPE {
                let ia = scalar_index(nodes, a);
                gravity_scale[ia] += g[a];
                for b in 0..N_SHAPE {
                    trip.push(Triplet::new(ia, scalar_index(nodes, b), m[a * N_SHAPE + b]));
                }
            }
        }
        let scalar_mass = SparseColMat::try_new_from_triplets(ns, ns, &trip)
            .map_err(|e| AncfError::NonFinite { what: format!("mass matrix assembly: {e:?}"), element: 0 })?;
        let (nv, np) = (tables.viscous.len(), tables.penalty.len());
        let mut dn_t = Mat::zeros(3 * (nv + np), N_SHAPE);
        for (p, dn) in tables.viscous.dn.iter().chain(&tables.penalty.dn).enumerate() {
            for a in 0..N_SHAPE {
                for j in 0..3 {
                    dn_t[(3 * p + j, a)] = dn[a][j];
                }
            }
        }
        Ok(Self { mesh, fluid, tables, elements, scalar_mass, gravity_scale, dn_t })
    }

    /// Number of generalized coordinates (12 per node).
    pub fn n_coords(&self) -> usize {
        self.mesh.n_coords()
    }

    /// Reference (initial) coordinates.
    pub fn reference_coordinates(&self) -> Vec<f64> {
        self.mesh.reference_coordinates()
    }

    /// The 4N×4N scalar mass matrix M_s (full mass = M_s ⊗ I₃).
    pub fn scalar_mass(&self) -> &SparseColMat<usize, f64> {
        &self.scalar_mass
    }

    /// Total mass ∫ρ dV₀ (sum of the position–position block of M_s).
    pub fn total_mass(&self) -> f64 {
        self.gravity_scale.iter().step_by(4).sum()
    }

    /// Reference volume ∫ dV₀ from the element reference data.
    pub fn reference_volume(&self) -> f64 {
        self.elements.iter().map(|e| e.volume).sum()
    }

    /// ∫ρ N dV₀ per scalar index: the gravity force is this ⊗ g.
    pub fn gravity_scale(&self) -> &[f64] {
        &self.gravity_scale
    }

    /// Generalized gravity force for the acceleration of gravity `g` (m/s²).
    pub fn gravity_force(&self, g: [f64; 3]) -> Vec<f64> {
        self.gravity_scale.iter().flat_map(|s| [s * g[0], s * g[1], s * g[2]]).collect()
    }

    /// ∫ρ r dV₀ (first moment of mass); linear in e.
    pub fn mass_moment(&self, e: &[f64]) -> [f64; 3] {
        let mut m = [0.0; 3];
        for (s, x) in self.gravity_scale.iter().zip(e.chunks_exact(3)) {
            for i in 0..3 {
                m[i] += s * x[i];
            }
        }
        m
    }

    /// Centre of mass ∫ρ r dV₀ / m (seed 000 §4.3).
    pub fn center_of_mass(&self, e: &[f64]) -> [f64; 3] {
        let m = self.total_mass();
        let s = self.mass_moment(e);
        [s[0] / m, s[1] / m, s[2] / m]
    }

    /// Kinetic energy ½ ėᵀ M ė.
    pub fn kinetic_energy(&self, edot: &[f64]) -> f64 {
        let m = self.scalar_mass.as_ref();
        let mut t = 0.0;
        for j in 0..m.ncols() {
            let vj = &edot[3 * j..3 * j + 3];
            for (i, v) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
                let vi = &edot[3 * i..3 * i + 3];
                t += v * (vi[0] * vj[0] + vi[1] * vj[1] + vi[2] * vj[2]);
            }
        }
        0.5 * t
    }

    /// Gravitational potential energy −g · ∫ρ r dV₀.
    pub fn potential_energy(&self, e: &[f64], g: [f64; 3]) -> f64 {
        let s = self.mass_moment(e);
        -(g[0] * s[0] + g[1] * s[1] + g[2] * s[2])
    }

    /// Current fluid volume ∫ J dV₀.
    pub fn volume(&self, e: &[f64]) -> f64 {
        self.elements
            .iter()
            .zip(&self.mesh.elements)
            .map(|(el, nodes)| el.volume_current(&gather_compact_flat(e, nodes), &self.tables))
            .sum()
    }

    /// Global index of compact coordinate `3a + i` of element `el`.
    pub fn global_index(&self, el: usize, compact: usize) -> usize {
        let a = compact / 3;
        3 * scalar_index(&self.mesh.elements[el], a) + compact % 3
    }

    /// Compact coordinates of element `el` gathered from a global vector.
    pub fn element_coordinates(&self, el: usize, e: &[f64]) -> Compact {
        gather_compact_flat(e, &self.mesh.elements[el])
    }

    /// Internal force and exact Jacobians of one element (reference scalar path).
    pub fn element_tangent(&self, el: usize, e: &[f64], edot: &[f64]) -> Result<([f64; N_COORDS], ElementJacobian)> {
        let mut f = [0.0; N_COORDS];
        let mut k = vec![0.0; N_COORDS * N_COORDS];
        let mut c = vec![0.0; N_COORDS * N_COORDS];
        let ec = self.element_coordinates(el, e);
        let ed = self.element_coordinates(el, edot);
        self.elements[el].internal_force(el, &self.fluid, &self.tables, &ec, &ed, &mut f, Some((&mut k, &mut c)))?;
        Ok((f, ElementJacobian { stiffness: k, damping: c }))
    }

    /// Jacobians of every element, computed in parallel.
    pub fn element_jacobians(&self, e: &[f64], edot: &[f64]) -> Result<Vec<ElementJacobian>> {
        self.check_state(e, edot)?;
        (0..self.elements.len()).into_par_iter().map(|el| self.element_tangent(el, e, edot).map(|x| x.1)).collect()
    }

    /// Generalized internal forces f(e, ė) (viscous + penalty), element by element with
    /// the scalar kernel. Reference implementation for [`Self::internal_forces`].
    pub fn internal_forces_scalar(&self, e: &[f64], edot: &[f64], out: &mut [f64]) -> Result<()> {
        self.check_state(e, edot)?;
        check_len("out", out.len(), self.n_coords())?;
        out.fill(0.0);
        let mut f = [0.0; N_COORDS];
        for (el, (r, nodes)) in self.elements.iter().zip(&self.mesh.elements).enumerate() {
            let ec = gather_compact_flat(e, nodes);
            let ed = gather_compact_flat(edot, nodes);
            r.internal_force(el, &self.fluid, &self.tables, &ec, &ed, &mut f, None)?;
            self.scatter(el, &f, out);
        }
        Ok(())
    }

    /// Generalized internal forces f(e, ė), batched and parallel. Deterministic.
    pub fn internal_forces(&self, e: &[f64], edot: &[f64], out: &mut [f64]) -> Result<()> {
        self.check_state(e, edot)?;
        check_len("out", out.len(), self.n_coords())?;
        let nel = self.elements.len();
        let chunks: Vec<Result<Vec<[f64; N_COORDS]>>> = (0..nel.div_ceil(CHUNK))
            .into_par_iter()
            .map(|c| {
                let lo = c * CHUNK;
                let hi = (lo + CHUNK).min(nel);
                self.batched_chunk(lo, hi, e, edot)
            })
            .collect();
        out.fill(0.0);
        let mut el = 0;
        for ch in chunks {
            for f in ch? {
                self.scatter(el, &f, out);
                el += 1;
            }
        }
        Ok(())
    }

    fn check_state(&self, e: &[f64], edot: &[f64]) -> Result<()> {
        check_len("e", e.len(), self.n_coords())?;
        check_len("edot", edot.len(), self.n_coords())
    }

    fn scatter(&self, el: usize, f: &[f64; N_COORDS], out: &mut [f64]) {
        let nodes = &self.mesh.elements[el];
        for a in 0..N_SHAPE {
            let g = 3 * scalar_index(nodes, a);
            out[g] += f[3 * a];
            out[g + 1] += f[3 * a + 1];
            out[g + 2] += f[3 * a + 2];
        }
    }

    /// Forces of elements `lo..hi` through two GEMMs.
    fn batched_chunk(&self, lo: usize, hi: usize, e: &[f64], edot: &[f64]) -> Result<Vec<[f64; N_COORDS]>> {
        let nb = hi - lo;
        let nv = self.tables.viscous.len();
        let npt = nv + self.tables.penalty.len();
        let mut ehat = Mat::<f64>::zeros(N_SHAPE, 6 * nb);
        for (b, el) in (lo..hi).enumerate() {
            let nodes = &self.mesh.elements[el];
            let scale = &self.elements[el].scale;
            for a in 0..N_SHAPE {
                let g = 3 * scalar_index(nodes, a);
                for i in 0..3 {
                    ehat[(a, 6 * b + i)] = scale[a] * e[g + i];
                    ehat[(a, 6 * b + 3 + i)] = scale[a] * edot[g + i];
                }
            }
        }
        let mut fh = Mat::<f64>::zeros(3 * npt, 6 * nb);
        matmul(fh.as_mut(), Accum::Replace, self.dn_t.as_ref(), ehat.as_ref(), 1.0, Par::Seq);
        let mut ph = Mat::<f64>::zeros(3 * npt, 3 * nb);
        let has_penalty = self.fluid.bulk_penalty != 0.0 || self.fluid.bulk_damping != 0.0;
        for (b, el) in (lo..hi).enumerate() {
            let r = &self.elements[el];
            for p in 0..npt {
                let (rp, deviatoric) = if p < nv { (&r.viscous[p], true) } else { (&r.penalty[p - nv], false) };
                if !deviatoric && !has_penalty {
                    continue;
                }
                let mut fhat = M3::zeros();
                let mut fdhat = M3::zeros();
                for i in 0..3 {
                    for j in 0..3 {
                        fhat[(i, j)] = fh[(3 * p + j, 6 * b + i)];
                        fdhat[(i, j)] = fh[(3 * p + j, 6 * b + 3 + i)];
                    }
                }
                let f = fhat * rp.jinv;
                let fd = fdhat * rp.jinv;
                let pk = if deviatoric {
                    self.fluid.deviatoric_stress(&f, &fd, None).ok_or(AncfError::InvertedElement {
                        element: el,
                        point: p,
                        j: f.determinant(),
                    })?
                } else {
                    self.fluid.volumetric_stress(&f, &fd, None).0
                };
                let phat = rp.wdet * pk * rp.jinv.transpose();
                for i in 0..3 {
                    for j in 0..3 {
                        ph[(3 * p + j, 3 * b + i)] = phat[(i, j)];
                    }
                }
            }
        }
        let mut fo = Mat::<f64>::zeros(N_SHAPE, 3 * nb);
        matmul(fo.as_mut(), Accum::Replace, self.dn_t.transpose(), ph.as_ref(), 1.0, Par::Seq);
        let mut out = vec![[0.0; N_COORDS]; nb];
        for (b, el) in (lo..hi).enumerate() {
            let scale = &self.elements[el].scale;
            for a in 0..N_SHAPE {
                for i in 0..3 {
                    out[b][3 * a + i] = scale[a] * fo[(a, 3 * b + i)];
                }
            }
            if out[b].iter().any(|v| !v.is_finite()) {
                return Err(AncfError::NonFinite { what: "element internal force".into(), element: el });
            }
        }
        Ok(out)
    }
}

/// Scalar index (4·node + vector) of compact column `a` of an element.
#[inline]
pub fn scalar_index(nodes: &[usize; 8], a: usize) -> usize {
    4 * nodes[a / 4] + a % 4
}

pub(crate) fn gather_compact(nodes_ref: &[[f64; COORDS_PER_NODE]], nodes: &[usize; 8]) -> Compact {
    let mut c = [[0.0; 3]; N_SHAPE];
    for a in 0..N_SHAPE {
        let n = &nodes_ref[nodes[a / 4]];
        let m = a % 4;
        c[a] = [n[3 * m], n[3 * m + 1], n[3 * m + 2]];
    }
    c
}

fn gather_compact_flat(e: &[f64], nodes: &[usize; 8]) -> Compact {
    let mut c = [[0.0; 3]; N_SHAPE];
    for a in 0..N_SHAPE {
        let g = 3 * scalar_index(nodes, a);
        c[a] = [e[g], e[g + 1], e[g + 2]];
    }
    c
}

/// Apply a rigid motion to a global coordinate vector: positions x ↦ R x + t, gradients
/// g ↦ R g. With `omega` and `v`, also returns the rigid velocity ė (ω × x + v for
/// positions, ω × (R g) for gradients).
pub fn rigid_motion(e: &[f64], rot: &M3, t: [f64; 3], omega: [f64; 3], v: [f64; 3]) -> (Vec<f64>, Vec<f64>) {
    let mut out = vec![0.0; e.len()];
    let mut vel = vec![0.0; e.len()];
    let w = Vector3::from(omega);
    for (s, (x, (o, d))) in e.chunks_exact(3).zip(out.chunks_exact_mut(3).zip(vel.chunks_exact_mut(3))).enumerate() {
        let is_pos = s % 4 == 0;
        let y = rot * Vector3::new(x[0], x[1], x[2]);
        let y = if is_pos { y + Vector3::from(t) } else { y };
        let dv = w.cross(&y) + if is_pos { Vector3::from(v) } else { Vector3::zeros() };
        o.copy_from_slice(y.as_slice());
        d.copy_from_slice(dv.as_slice());
    }
    (out, vel)
}
