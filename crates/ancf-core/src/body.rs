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
//!
//! **Non-affine-mode control.** [`crate::Fluid::hourglass_stabilization`] G_h (Pa) adds the
//! stored energy Σ_el ∫ G_h |F − F̄|² dV₀, F̄ the element's mean deformation gradient over the
//! viscous rule. F is linear in the element coordinates, so this is ½ eᵀ (2 G_h H ⊗ I₃) e with a
//! constant 32×32 H per element ([`crate::element::ElementRef::non_affine_compact`], built with
//! the body): a constant stiffness added to the element forces and Jacobians, and its energy to
//! [`FluidBody::stabilization_energy`]. It vanishes for every affine deformation of an element,
//! large rotations, stretches and shears included, so unlike the shear stabilization (the
//! deviatoric strain from the rest shape) it does not resist a liquid's large, smooth motion,
//! only deformation that varies inside an element. It is objective (|R(F − F̄)| = |F − F̄|). Off
//! by default; docs/validation.md, "The ECP scenes' lateral channels", measures it.

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

/// Reusable buffers of [`FluidBody::internal_forces_with`]: one set per chunk of
/// elements, sized on first use. A workspace can serve any body (it is resized when the
/// chunks change); reusing it makes the force evaluation allocation-free.
#[derive(Debug, Clone, Default)]
pub struct ForceWorkspace {
    chunks: Vec<ChunkBuffers>,
}

/// Buffers of one chunk of [`CHUNK`] elements (see [`FluidBody::batched_chunk`]).
#[derive(Debug, Clone)]
struct ChunkBuffers {
    /// Scaled coordinates and velocities, 32 × 6n_b.
    ehat: Mat<f64>,
    /// ∂r/∂ξ and ∂ṙ/∂ξ at the points, 3n_p × 6n_b.
    fh: Mat<f64>,
    /// Scaled stresses, 3n_p × 3n_b.
    ph: Mat<f64>,
    /// Scaled forces, 32 × 3n_b.
    fo: Mat<f64>,
    /// Element forces of the chunk.
    out: Vec<[f64; N_COORDS]>,
    /// Outcome of the chunk's last evaluation.
    status: Result<()>,
}

impl ChunkBuffers {
    fn new() -> Self {
        Self { ehat: Mat::new(), fh: Mat::new(), ph: Mat::new(), fo: Mat::new(), out: Vec::new(), status: Ok(()) }
    }

    /// Sizes the buffers for `nb` elements and `npt` force points (no allocation when
    /// the sizes are unchanged).
    fn size(&mut self, nb: usize, npt: usize) {
        let fit = |m: &mut Mat<f64>, r: usize, c: usize| {
            if m.nrows() != r || m.ncols() != c {
                *m = Mat::zeros(r, c);
            }
        };
        fit(&mut self.ehat, N_SHAPE, 6 * nb);
        fit(&mut self.fh, 3 * npt, 6 * nb);
        fit(&mut self.ph, 3 * npt, 3 * nb);
        fit(&mut self.fo, N_SHAPE, 3 * nb);
        self.out.resize(nb, [0.0; N_COORDS]);
    }
}

/// Dense per-element Jacobians of the internal force.
#[derive(Debug, Clone)]
pub struct ElementJacobian {
    /// K = ∂f/∂e, row-major 96×96 in compact ordering `3a + i`.
    pub stiffness: Vec<f64>,
    /// C = ∂f/∂ė, row-major 96×96.
    pub damping: Vec<f64>,
}

/// Extremes of the volume ratio J = det F over a body ([`FluidBody::volume_ratio_range`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct VolumeRatioRange {
    /// Smallest J.
    pub min: f64,
    /// Element of the smallest J.
    pub element: usize,
    /// Its point: viscous points first, then penalty, then mass points.
    pub point: usize,
    /// Largest J.
    pub max: f64,
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
    /// Per element, 2 G_h H (row-major 32×32, [`ElementRef::non_affine_compact`]): the
    /// constant stiffness of the non-affine-mode control; empty when G_h = 0.
    non_affine: Vec<Vec<f64>>,
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
        let gh = fluid.hourglass_stabilization;
        let non_affine = if gh > 0.0 {
            elements
                .iter()
                .map(|el| el.non_affine_compact(&tables).into_iter().map(|h| 2.0 * gh * h).collect())
                .collect()
        } else {
            Vec::new()
        };
        Ok(Self { mesh, fluid, tables, elements, scalar_mass, gravity_scale, dn_t, non_affine })
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

    /// `out[i] −= (scale · M_ij) · a[j]` for the full mass M = M_s ⊗ I₃ (`a`, `out`: this
    /// body's coordinates), each row's terms by increasing column: the same sums as a product
    /// over M's entries sorted by row and column, with a third of the index traffic.
    pub fn subtract_mass_product(&self, a: &[f64], scale: f64, out: &mut [f64]) {
        let m = self.scalar_mass.as_ref();
        for j in 0..m.ncols() {
            let aj = [a[3 * j], a[3 * j + 1], a[3 * j + 2]];
            for (i, val) in m.row_idx_of_col(j).zip(m.val_of_col(j)) {
                let c = scale * val;
                for d in 0..3 {
                    out[3 * i + d] -= c * aj[d];
                }
            }
        }
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

    /// Stored energy of the volumetric penalty, Σ ∫ ½ k (J − 1)² dV₀ (J).
    pub fn penalty_energy(&self, e: &[f64]) -> f64 {
        self.elements
            .iter()
            .zip(&self.mesh.elements)
            .map(|(el, nodes)| el.penalty_energy(&gather_compact_flat(e, nodes), &self.tables, self.fluid.bulk_penalty))
            .sum()
    }

    /// Stored energy of the shear stabilization, Σ ∫ G_s dev(E):dev(E) dV₀ (J); 0 without it.
    pub fn stabilization_energy(&self, e: &[f64]) -> f64 {
        let mut energy = 0.0;
        if self.fluid.shear_stabilization != 0.0 {
            energy += self
                .elements
                .iter()
                .zip(&self.mesh.elements)
                .map(|(el, nodes)| el.stabilization_energy(&gather_compact_flat(e, nodes), &self.tables, &self.fluid))
                .sum::<f64>();
        }
        for (k, nodes) in self.non_affine.iter().zip(&self.mesh.elements) {
            let ec = gather_compact_flat(e, nodes);
            let mut f = [0.0; N_COORDS];
            add_non_affine(k, &ec, &mut f, None);
            energy += 0.5 * (0..N_SHAPE).map(|a| (0..3).map(|i| ec[a][i] * f[3 * a + i]).sum::<f64>()).sum::<f64>();
        }
        energy
    }

    /// Adds the non-affine-mode control's force (and stiffness) of element `el`, if any.
    fn non_affine_term(&self, el: usize, ec: &Compact, f: &mut [f64; N_COORDS], k: Option<&mut [f64]>) {
        if let Some(m) = self.non_affine.get(el) {
            add_non_affine(m, ec, f, k);
        }
    }

    /// The smallest volume ratio J = det F over every quadrature point of every element
    /// (all three rules, see [`ElementRef::volume_ratio_range`]) and the largest.
    pub fn volume_ratio_range(&self, e: &[f64]) -> VolumeRatioRange {
        let mut r = VolumeRatioRange { min: f64::INFINITY, element: 0, point: 0, max: f64::NEG_INFINITY };
        for (k, (el, nodes)) in self.elements.iter().zip(&self.mesh.elements).enumerate() {
            let (lo, p, hi) = el.volume_ratio_range(&gather_compact_flat(e, nodes), &self.tables);
            if lo.is_nan() || lo < r.min {
                (r.min, r.element, r.point) = (lo, k, p);
            }
            r.max = r.max.max(hi);
        }
        r
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
        self.non_affine_term(el, &ec, &mut f, Some(&mut k));
        Ok((f, ElementJacobian { stiffness: k, damping: c }))
    }

    /// Jacobians of every element, computed in parallel.
    pub fn element_jacobians(&self, e: &[f64], edot: &[f64]) -> Result<Vec<ElementJacobian>> {
        self.check_state(e, edot)?;
        (0..self.elements.len()).into_par_iter().map(|el| self.element_tangent(el, e, edot).map(|x| x.1)).collect()
    }

    /// [`Self::element_jacobians`] into `out`, reusing its storage (no allocation once it
    /// holds one Jacobian per element; rayon's scheduling may allocate with more than one
    /// thread). Identical values.
    pub fn element_jacobians_into(&self, e: &[f64], edot: &[f64], out: &mut Vec<ElementJacobian>) -> Result<()> {
        self.check_state(e, edot)?;
        let n2 = N_COORDS * N_COORDS;
        out.resize_with(self.elements.len(), || ElementJacobian { stiffness: vec![0.0; n2], damping: vec![0.0; n2] });
        out.par_iter_mut().enumerate().try_for_each(|(el, jac)| {
            let mut f = [0.0; N_COORDS];
            let ec = self.element_coordinates(el, e);
            let ed = self.element_coordinates(el, edot);
            // Zeroes the Jacobians before accumulating into them.
            self.elements[el].internal_force(
                el,
                &self.fluid,
                &self.tables,
                &ec,
                &ed,
                &mut f,
                Some((&mut jac.stiffness, &mut jac.damping)),
            )?;
            self.non_affine_term(el, &ec, &mut f, Some(&mut jac.stiffness));
            Ok(())
        })
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
            self.non_affine_term(el, &ec, &mut f, None);
            self.scatter(el, &f, out);
        }
        Ok(())
    }

    /// Generalized internal forces f(e, ė), batched and parallel. Deterministic.
    /// Allocates its buffers; [`Self::internal_forces_with`] reuses them.
    pub fn internal_forces(&self, e: &[f64], edot: &[f64], out: &mut [f64]) -> Result<()> {
        self.internal_forces_with(&mut ForceWorkspace::default(), e, edot, out)
    }

    /// [`Self::internal_forces`] with reusable buffers: no allocation once `ws` has been
    /// used with this body (on the calling thread with one rayon thread; rayon's own
    /// scheduling may allocate with more). Results are bitwise identical for any thread
    /// count and to [`Self::internal_forces`].
    pub fn internal_forces_with(
        &self,
        ws: &mut ForceWorkspace,
        e: &[f64],
        edot: &[f64],
        out: &mut [f64],
    ) -> Result<()> {
        self.check_state(e, edot)?;
        check_len("out", out.len(), self.n_coords())?;
        let nel = self.elements.len();
        let npt = self.tables.viscous.len() + self.tables.penalty.len();
        let n_chunks = nel.div_ceil(CHUNK);
        if ws.chunks.len() != n_chunks {
            ws.chunks.resize_with(n_chunks, ChunkBuffers::new);
        }
        ws.chunks.par_iter_mut().enumerate().for_each(|(c, buf)| {
            let lo = c * CHUNK;
            let hi = (lo + CHUNK).min(nel);
            buf.size(hi - lo, npt);
            buf.status = self.batched_chunk(lo, hi, e, edot, buf);
        });
        out.fill(0.0);
        let mut el = 0;
        for buf in &mut ws.chunks {
            std::mem::replace(&mut buf.status, Ok(()))?;
            for f in &buf.out {
                self.scatter(el, f, out);
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

    /// Forces of elements `lo..hi` through two GEMMs, into `buf.out` (`buf` sized for
    /// the chunk by [`ChunkBuffers::size`]).
    fn batched_chunk(&self, lo: usize, hi: usize, e: &[f64], edot: &[f64], buf: &mut ChunkBuffers) -> Result<()> {
        let nv = self.tables.viscous.len();
        let npt = nv + self.tables.penalty.len();
        let ChunkBuffers { ehat, fh, ph, fo, out, .. } = buf;
        // Every entry of `ehat`, `fh`, `fo` and `out` is written below; `ph` keeps zeros in
        // the rows of the points that are skipped.
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
        matmul(fh.as_mut(), Accum::Replace, self.dn_t.as_ref(), ehat.as_ref(), 1.0, Par::Seq);
        crate::clear_upper_simd();
        let has_penalty = self.fluid.bulk_penalty != 0.0 || self.fluid.bulk_damping != 0.0;
        if !has_penalty {
            ph.fill(0.0);
        }
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
        matmul(fo.as_mut(), Accum::Replace, self.dn_t.transpose(), ph.as_ref(), 1.0, Par::Seq);
        crate::clear_upper_simd();
        for (b, el) in (lo..hi).enumerate() {
            let scale = &self.elements[el].scale;
            for a in 0..N_SHAPE {
                for i in 0..3 {
                    out[b][3 * a + i] = scale[a] * fo[(a, 3 * b + i)];
                }
            }
            if !self.non_affine.is_empty() {
                self.non_affine_term(el, &gather_compact_flat(e, &self.mesh.elements[el]), &mut out[b], None);
            }
            if out[b].iter().any(|v| !v.is_finite()) {
                return Err(AncfError::NonFinite { what: "element internal force".into(), element: el });
            }
        }
        Ok(())
    }
}

/// f += K e and, with `k`, the 96×96 stiffness += K ⊗ I₃, for a compact 32×32 constant
/// stiffness `m` (row-major, symmetric) and element coordinates `ec`.
fn add_non_affine(m: &[f64], ec: &Compact, f: &mut [f64; N_COORDS], k: Option<&mut [f64]>) {
    for a in 0..N_SHAPE {
        let row = &m[a * N_SHAPE..(a + 1) * N_SHAPE];
        for i in 0..3 {
            f[3 * a + i] += (0..N_SHAPE).map(|b| row[b] * ec[b][i]).sum::<f64>();
        }
    }
    if let Some(k) = k {
        for a in 0..N_SHAPE {
            for b in 0..N_SHAPE {
                for i in 0..3 {
                    k[(3 * a + i) * N_COORDS + 3 * b + i] += m[a * N_SHAPE + b];
                }
            }
        }
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

#[cfg(test)]
mod tests {
    use super::*;
    use crate::constitutive::Rheology;
    use crate::mesh::box_mesh;

    /// Coordinates and velocities.
    type State = (Vec<f64>, Vec<f64>);

    /// A 5×2×1 box mesh and three deformed, moving states.
    fn body_and_states(bulk_penalty: f64) -> (FluidBody, Vec<State>) {
        let mesh = box_mesh([0.0; 3], [2.0, 1.0, 0.5], [5, 2, 1]).unwrap();
        let fluid = Fluid::new(900.0, Rheology::Newtonian { viscosity: 0.3 }, bulk_penalty).unwrap();
        let body = FluidBody::new(mesh, fluid, QuadratureOptions::default()).unwrap();
        let e0 = body.reference_coordinates();
        let states = (0..3)
            .map(|k| {
                let s = 0.01 * (k + 1) as f64;
                let e: Vec<f64> =
                    e0.iter().enumerate().map(|(i, x)| x + s * ((i * 7 % 13) as f64 / 13.0 - 0.5)).collect();
                let v: Vec<f64> = (0..e0.len()).map(|i| s * ((i * 5 % 11) as f64 / 11.0 - 0.5)).collect();
                (e, v)
            })
            .collect();
        (body, states)
    }

    /// The force `f` at `e` is the gradient of `energy` along `v`: central differences of step
    /// `h` agree with f·v within `tol` relative.
    fn assert_potential(energy: impl Fn(&[f64]) -> f64, e: &[f64], v: &[f64], f: &[f64], h: f64, tol: f64) {
        let at = |s: f64| energy(&e.iter().zip(v).map(|(x, d)| x + s * d).collect::<Vec<_>>());
        let du = (at(h) - at(-h)) / (2.0 * h);
        let fd: f64 = f.iter().zip(v).map(|(a, b)| a * b).sum();
        assert!((du - fd).abs() < tol * fd.abs(), "dU = {du}, f.d = {fd}");
    }

    /// A reused workspace gives bit-identical forces to fresh buffers, state after state,
    /// with and without the penalty terms (whose skipped rows must stay zero).
    #[test]
    fn reused_force_workspace_is_bit_identical() {
        for penalty in [2e6, 0.0] {
            let (body, states) = body_and_states(penalty);
            let mut ws = ForceWorkspace::default();
            let n = body.n_coords();
            for (e, v) in &states {
                let (mut fresh, mut reused) = (vec![0.0; n], vec![1.0; n]);
                body.internal_forces(e, v, &mut fresh).unwrap();
                body.internal_forces_with(&mut ws, e, v, &mut reused).unwrap();
                assert!(fresh.iter().any(|x| *x != 0.0));
                assert_eq!(fresh, reused, "penalty {penalty}");
            }
        }
    }

    /// The penalty energy is the potential of the penalty force: with no viscosity, no
    /// bulk damping and ė = 0 the internal force is ∂U/∂e (central differences along a
    /// direction), and U vanishes in the reference state.
    #[test]
    fn penalty_energy_is_the_potential_of_the_internal_force() {
        let (mut body, states) = body_and_states(2e6);
        body.fluid.rheology = Rheology::Newtonian { viscosity: 0.0 };
        body.fluid.bulk_damping = 0.0;
        assert!(body.penalty_energy(&body.reference_coordinates()) < 1e-20);
        let n = body.n_coords();
        for (e, v) in &states {
            let mut f = vec![0.0; n];
            body.internal_forces(e, &vec![0.0; n], &mut f).unwrap();
            assert!(body.penalty_energy(e) > 0.0);
            assert_potential(|x| body.penalty_energy(x), e, v, &f, 1e-6, 1e-6);
        }
    }

    /// The body's coordinates under x → A x + c (positions) and r_ξ → A r_ξ (gradients).
    fn affine(e: &[f64], a: &M3, c: [f64; 3]) -> Vec<f64> {
        let mut out = e.to_vec();
        for (s, (o, x)) in out.chunks_exact_mut(3).zip(e.chunks_exact(3)).enumerate() {
            let y = a * nalgebra::Vector3::new(x[0], x[1], x[2]);
            let shift = if s % 4 == 0 { c } else { [0.0; 3] };
            for i in 0..3 {
                o[i] = y[i] + shift[i];
            }
        }
        out
    }

    fn non_affine_body(gh: f64) -> (FluidBody, Vec<State>) {
        let (mut body, states) = body_and_states(0.0);
        let mut fluid = body.fluid;
        fluid.rheology = Rheology::Newtonian { viscosity: 0.0 };
        fluid.hourglass_stabilization = gh;
        body = FluidBody::new(body.mesh.clone(), fluid, QuadratureOptions::default()).unwrap();
        (body, states)
    }

    /// The non-affine-mode control: its force is the gradient of its stored energy (through
    /// the batched and the scalar force paths alike), and its stiffness is that force's exact
    /// derivative.
    #[test]
    fn non_affine_control_is_the_potential_of_its_force_and_its_stiffness_is_exact() {
        let (body, states) = non_affine_body(50.0);
        let n = body.n_coords();
        let zero = vec![0.0; n];
        let least = states.iter().map(|(e, _)| body.stabilization_energy(e)).fold(f64::INFINITY, f64::min);
        assert!(body.stabilization_energy(&body.reference_coordinates()).abs() < 1e-10 * least);
        for (e, v) in &states {
            let (mut f, mut fs) = (vec![0.0; n], vec![0.0; n]);
            body.internal_forces(e, &zero, &mut f).unwrap();
            body.internal_forces_scalar(e, &zero, &mut fs).unwrap();
            let scale = f.iter().fold(0.0f64, |m, x| m.max(x.abs()));
            assert!(scale > 0.0 && f.iter().zip(&fs).all(|(a, b)| (a - b).abs() <= 1e-12 * scale));
            // the energy is quadratic and the force linear in e: central differences are exact
            // but for round-off, so a long step keeps that small
            let h = 1e-2;
            assert!(body.stabilization_energy(e) > 0.0);
            assert_potential(|x| body.stabilization_energy(x), e, v, &f, h, 1e-7);
            // the stiffness of element 3 against central differences of its force
            let (_, jac) = body.element_tangent(3, e, &zero).unwrap();
            let dv: Vec<f64> = (0..N_COORDS).map(|i| ((i * 3 % 7) as f64 - 3.0) / 7.0).collect();
            let mut ep = e.clone();
            let mut em = e.clone();
            for (a, d) in dv.iter().enumerate() {
                let g = body.global_index(3, a);
                ep[g] += h * d;
                em[g] -= h * d;
            }
            let (fp, _) = body.element_tangent(3, &ep, &zero).unwrap();
            let (fm, _) = body.element_tangent(3, &em, &zero).unwrap();
            for r in 0..N_COORDS {
                let kd: f64 = (0..N_COORDS).map(|c| jac.stiffness[r * N_COORDS + c] * dv[c]).sum();
                let fdr = (fp[r] - fm[r]) / (2.0 * h);
                assert!((kd - fdr).abs() <= 1e-8 * (1.0 + fdr.abs()), "row {r}: K dv = {kd}, FD {fdr}");
            }
        }
    }

    /// The control stores no energy and exerts no force under any affine map of the
    /// reference (a large rotation, stretch and shear, and a shift), is invariant under a
    /// rigid rotation of a deformed state, and stores energy in a non-affine one.
    #[test]
    fn non_affine_control_ignores_affine_and_rigid_motions() {
        let (body, states) = non_affine_body(50.0);
        let n = body.n_coords();
        let e0 = body.reference_coordinates();
        let rot = *nalgebra::Rotation3::from_euler_angles(0.7, -0.4, 1.9).matrix();
        let a = rot * M3::new(1.6, 0.5, -0.3, 0.1, 0.7, 0.4, 0.2, -0.2, 1.1);
        let mapped = affine(&e0, &a, [3.0, -1.0, 0.5]);
        let mut f = vec![0.0; n];
        body.internal_forces(&mapped, &vec![0.0; n], &mut f).unwrap();
        let (deformed, _) = &states[2];
        let e_scale = body.stabilization_energy(deformed);
        assert!(e_scale > 0.0);
        assert!(body.stabilization_energy(&mapped).abs() < 1e-10 * e_scale);
        let mut f_def = vec![0.0; n];
        body.internal_forces(deformed, &vec![0.0; n], &mut f_def).unwrap();
        let f_scale = f_def.iter().fold(0.0f64, |m, x| m.max(x.abs()));
        assert!(f.iter().all(|x| x.abs() < 1e-9 * f_scale));
        let turned = affine(deformed, &rot, [0.0; 3]);
        assert!((body.stabilization_energy(&turned) - e_scale).abs() < 1e-10 * e_scale);
    }

    /// The volume ratio range: 1 in the reference state, the extremes of a uniform
    /// stretch, and the smallest at its element when one element is squashed.
    #[test]
    fn volume_ratio_range_sees_stretch_and_a_squashed_element() {
        let (body, _) = body_and_states(2e6);
        let e0 = body.reference_coordinates();
        let r = body.volume_ratio_range(&e0);
        assert!((r.min - 1.0).abs() < 1e-12 && (r.max - 1.0).abs() < 1e-12, "{r:?}");
        // x ↦ 1.2 x: positions and x-gradients scale
        let stretched: Vec<f64> = e0.iter().enumerate().map(|(i, x)| if i % 3 == 0 { 1.2 * x } else { *x }).collect();
        let r = body.volume_ratio_range(&stretched);
        assert!((r.min - 1.2).abs() < 1e-12 && (r.max - 1.2).abs() < 1e-12, "{r:?}");
        // flatten the z-gradient of one node of element 3: J drops there, first
        let mut e = e0.clone();
        let node = body.mesh.elements[3][6];
        e[12 * node + 3 * 3 + 2] *= -1.0;
        let r = body.volume_ratio_range(&e);
        assert!(r.min < 1.0 && r.max > 1.0, "{r:?}");
        assert!(body.mesh.elements[r.element].contains(&node), "{r:?}");
    }

    /// Skipping a rule of the same order as an earlier one (the vehicle's 3/4/4, the SwRI
    /// scenes' 4/4/4) gives the smallest and largest J and the point of the smallest bit for
    /// bit as checking every rule, on folded and stretched states.
    #[test]
    fn volume_ratio_range_skips_repeated_rules_without_changing_the_result() {
        let mut rng = crate::rng::Rng::new(7);
        for (viscous, penalty, mass) in [(3, 4, 4), (4, 4, 4), (3, 3, 4), (3, 3, 3), (4, 3, 5)] {
            let mesh = box_mesh([0.0; 3], [1.0, 0.6, 0.4], [2, 2, 1]).unwrap();
            let fluid = Fluid::new(900.0, Rheology::Newtonian { viscosity: 0.3 }, 2e6).unwrap();
            let body = FluidBody::new(mesh, fluid, QuadratureOptions { viscous, penalty, mass }).unwrap();
            let t = &body.tables;
            let n_rules = t.viscous.dn.len() + t.penalty.dn.len() + t.mass.dn.len();
            let e0 = body.reference_coordinates();
            let mut seen_inside = false;
            for trial in 0..40 {
                let amp = if trial < 20 { 0.05 } else { 0.6 };
                let e: Vec<f64> = e0.iter().map(|x| x + 0.5 * amp * rng.uniform()).collect();
                for (el, nodes) in body.mesh.elements.iter().enumerate() {
                    let c = gather_compact_flat(&e, nodes);
                    let r = &body.elements[el];
                    let fast = r.volume_ratio_range(&c, &body.tables);
                    let all = r.volume_ratio_range_with(&c, &body.tables, false);
                    assert_eq!(fast.0.to_bits(), all.0.to_bits(), "{viscous}/{penalty}/{mass} trial {trial}");
                    assert_eq!((fast.1, fast.2.to_bits()), (all.1, all.2.to_bits()));
                    seen_inside |= all.1 < n_rules && all.1 > 0;
                }
            }
            assert!(seen_inside, "the smallest J fell on a force or mass point at least once");
        }
    }

    /// Reused element Jacobians equal freshly computed ones, state after state.
    #[test]
    fn reused_element_jacobians_are_identical() {
        let (body, states) = body_and_states(2e6);
        let mut jacs = Vec::new();
        for (e, v) in &states {
            let fresh = body.element_jacobians(e, v).unwrap();
            body.element_jacobians_into(e, v, &mut jacs).unwrap();
            assert_eq!(jacs.len(), fresh.len());
            for (a, b) in fresh.iter().zip(&jacs) {
                assert_eq!(a.stiffness, b.stiffness);
                assert_eq!(a.damping, b.damping);
            }
        }
    }
}
