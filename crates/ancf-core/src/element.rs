//! The 8-node ANCF brick element: reference data and element kernels.
//!
//! Notation (seed 000 §3): x is the straight configuration (a box of edge lengths
//! L_x, L_y, L_z), X the stress-free curved reference configuration, r the current one.
//! With the normalized coordinates ξ ∈ [−1, 1]³ and the scaled nodal coordinates
//! ê_a = s_a e_a (see [`crate::shape`]):
//!
//! - Ĵ₀ = ∂X/∂ξ = Σ_a ê₀_a ⊗ ∂n_a/∂ξ, constant in time;
//! - F = ∂r/∂X = (Σ_a ê_a ⊗ ∂n_a/∂ξ) Ĵ₀⁻¹, the deformation gradient (seed: J = J_e J₀⁻¹);
//! - dV₀ = det Ĵ₀ dξ, so a quadrature weight becomes w·det Ĵ₀.
//!
//! The generalized internal force is f = ∫ P : ∂F/∂e dV₀ (so that M ë = Q_ext − f),
//! with P the first Piola stress of [`crate::constitutive`]. Its Jacobians
//! K = ∂f/∂e and C = ∂f/∂ė are exact.
//!
//! Each force term uses its own quadrature rule ([`QuadratureOptions`]): at least 3×3×3
//! points for the viscous term (2×2×2 leaves 42 spurious zero-energy modes per element,
//! see `docs/architecture.md`), 3×3×3 for the volumetric penalty by default, and 4×4×4
//! points for the mass matrix (its integrand is of degree 6 per direction on an
//! undistorted element, so 4 points are exact). Seed 000 §8 uses a reduced penalty rule
//! against locking; we measured that with a low-viscosity liquid (light crude, water) the
//! 1- and 2-point penalty rules leave zero-stiffness modes that invert elements within
//! 0.2 s of hydrostatic settling, while 3×3×3 settles stably (`docs/architecture.md`).
//! Reduced rules remain selectable.

use faer::linalg::matmul::matmul;
use faer::{Accum, Mat, Par};
use nalgebra::Vector3;

use crate::constitutive::{DeviatoricPath, Fluid, M3, Tangent, cofactor, cofactor_derivative};
use crate::error::{AncfError, Result, invalid};
use crate::quadrature::{CubeRule, MAX_GAUSS_POINTS};
use crate::shape::{N_COORDS, N_SHAPE, normalized_shape, slope_scale};

/// Points per direction of each quadrature rule.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub struct QuadratureOptions {
    /// Rule for the viscous (deviatoric) stress; ≥ 3 (default 3).
    pub viscous: usize,
    /// Rule for the volumetric penalty and its damping (default 3; see below).
    pub penalty: usize,
    /// Rule for the mass matrix and gravity (default 4, exact).
    pub mass: usize,
}

impl Default for QuadratureOptions {
    fn default() -> Self {
        Self { viscous: 3, penalty: 3, mass: 4 }
    }
}

impl QuadratureOptions {
    /// Check the rules; the viscous rule must have at least 3 points per direction.
    pub fn validate(&self) -> Result<()> {
        let allowed = format!("an integer in [3, {MAX_GAUSS_POINTS}] (2 leaves spurious zero-energy modes)");
        if !(3..=MAX_GAUSS_POINTS).contains(&self.viscous) {
            return Err(invalid("quadrature.viscous", self.viscous, &allowed));
        }
        if !(1..=MAX_GAUSS_POINTS).contains(&self.penalty) {
            return Err(invalid("quadrature.penalty", self.penalty, &format!("an integer in [1, {MAX_GAUSS_POINTS}]")));
        }
        if !(2..=MAX_GAUSS_POINTS).contains(&self.mass) {
            return Err(invalid("quadrature.mass", self.mass, &format!("an integer in [2, {MAX_GAUSS_POINTS}]")));
        }
        Ok(())
    }
}

/// Normalized shape functions and derivatives tabulated at the points of one rule.
/// Shared by every element.
#[derive(Debug, Clone)]
pub struct ShapeTable {
    /// The quadrature rule.
    pub rule: CubeRule,
    /// n_a at each point.
    pub n: Vec<[f64; N_SHAPE]>,
    /// ∂n_a/∂ξ_j at each point.
    pub dn: Vec<[[f64; 3]; N_SHAPE]>,
}

impl ShapeTable {
    /// Tabulate the shape functions at an `n × n × n` Gauss rule.
    pub fn gauss(n: usize) -> Result<Self> {
        Ok(Self::of(CubeRule::gauss(n)?))
    }

    /// Tabulate the shape functions at the points of `rule`.
    pub fn of(rule: CubeRule) -> Self {
        let (nn, dn) = rule.points.iter().map(|p| normalized_shape(*p)).unzip();
        Self { rule, n: nn, dn }
    }

    /// Number of points.
    pub fn len(&self) -> usize {
        self.rule.len()
    }

    /// True when empty (never for a valid table).
    pub fn is_empty(&self) -> bool {
        self.rule.is_empty()
    }
}

/// Shape tables of the three rules.
#[derive(Debug, Clone)]
pub struct ShapeTables {
    /// Rule options used.
    pub options: QuadratureOptions,
    /// Viscous rule.
    pub viscous: ShapeTable,
    /// Penalty rule.
    pub penalty: ShapeTable,
    /// Mass rule.
    pub mass: ShapeTable,
    /// Check points of the volume ratio ([`ElementRef::volume_ratio_range`]): the 3×3×3
    /// Gauss–Lobatto points (corners, edge and face centres, centre), apart from the
    /// force and mass rules, so that a field folding between those points is seen.
    pub check: ShapeTable,
}

impl ShapeTables {
    /// Build the tables for the given options.
    pub fn new(options: QuadratureOptions) -> Result<Self> {
        options.validate()?;
        Ok(Self {
            options,
            viscous: ShapeTable::gauss(options.viscous)?,
            penalty: ShapeTable::gauss(options.penalty)?,
            mass: ShapeTable::gauss(options.mass)?,
            check: ShapeTable::of(CubeRule::lobatto(3)?),
        })
    }
}

/// Reference data of one element at one quadrature point.
#[derive(Debug, Clone, Copy)]
pub struct RefPoint {
    /// Ĵ₀⁻¹ = (∂X/∂ξ)⁻¹.
    pub jinv: M3,
    /// Quadrature weight times det Ĵ₀ (the reference volume the point represents).
    pub wdet: f64,
}

/// Reference (stress-free) data of one element.
#[derive(Debug, Clone)]
pub struct ElementRef {
    /// Straight-configuration edge lengths L_x, L_y, L_z.
    pub lengths: [f64; 3],
    /// Slope scales s_a.
    pub scale: [f64; N_SHAPE],
    /// Points of the viscous rule.
    pub viscous: Vec<RefPoint>,
    /// Points of the penalty rule.
    pub penalty: Vec<RefPoint>,
    /// Points of the mass rule.
    pub mass: Vec<RefPoint>,
    /// Reference volume V₀ (mass rule).
    pub volume: f64,
    /// Points of the check table ([`ShapeTables::check`]) with their index there, where
    /// the reference map is regular (det Ĵ₀ above 5 % of the element's mean; a corner of a
    /// nearly collapsed reference map is left out).
    pub check: Vec<(usize, RefPoint)>,
}

/// Element coordinates in compact form: `e[a]` is the 3-vector of compact column `a`.
pub type Compact = [[f64; 3]; N_SHAPE];

/// B_a = Ĵ₀⁻ᵀ ∂n_a/∂ξ at a point, the reference gradient of each scaled shape function
/// (so ∂F_iJ/∂ê_{a,i} = B_a,J).
#[inline]
fn shape_gradients(rp: &RefPoint, dn: &[[f64; 3]; N_SHAPE]) -> [[f64; 3]; N_SHAPE] {
    std::array::from_fn(|a| {
        let v = rp.jinv.transpose() * Vector3::new(dn[a][0], dn[a][1], dn[a][2]);
        [v[0], v[1], v[2]]
    })
}

/// Gradient ∂X/∂ξ of scaled compact coordinates at a point.
#[inline]
fn grad_xi(ehat: &Compact, dn: &[[f64; 3]; N_SHAPE]) -> M3 {
    let mut g = M3::zeros();
    for a in 0..N_SHAPE {
        for i in 0..3 {
            let v = ehat[a][i];
            g[(i, 0)] += v * dn[a][0];
            g[(i, 1)] += v * dn[a][1];
            g[(i, 2)] += v * dn[a][2];
        }
    }
    g
}

impl ElementRef {
    /// Reference data from the element's reference nodal coordinates `e0` (compact,
    /// physical gradients) and straight edge lengths. `index` is used in errors.
    pub fn new(index: usize, e0: &Compact, lengths: [f64; 3], tables: &ShapeTables) -> Result<Self> {
        for (j, l) in lengths.iter().enumerate() {
            if !(l.is_finite() && *l > 0.0) {
                return Err(invalid(&format!("element {index} length[{j}]"), l, "a finite number > 0"));
            }
        }
        let mut scale = [0.0; N_SHAPE];
        for (a, s) in scale.iter_mut().enumerate() {
            *s = slope_scale(a, &lengths);
        }
        let ehat = scaled(e0, &scale);
        let points = |t: &ShapeTable| -> Result<Vec<RefPoint>> {
            t.dn.iter()
                .zip(&t.rule.weights)
                .enumerate()
                .map(|(p, (dn, w))| {
                    let j0 = grad_xi(&ehat, dn);
                    let det = j0.determinant();
                    if !(det > 0.0) || !det.is_finite() {
                        return Err(AncfError::DegenerateReference { element: index, point: p, det });
                    }
                    Ok(RefPoint { jinv: j0.try_inverse().expect("det > 0"), wdet: w * det })
                })
                .collect()
        };
        let viscous = points(&tables.viscous)?;
        let penalty = points(&tables.penalty)?;
        let mass = points(&tables.mass)?;
        let volume = mass.iter().map(|p| p.wdet).sum();
        let check = tables
            .check
            .dn
            .iter()
            .enumerate()
            .filter_map(|(p, dn)| {
                let j0 = grad_xi(&ehat, dn);
                let det = j0.determinant();
                // a corner where the reference map nearly collapses (det below 5 % of the
                // element's mean) would turn round-off into arbitrary volume ratios
                (det > 0.05 * volume / 8.0 && det.is_finite())
                    .then(|| (p, RefPoint { jinv: j0.try_inverse().expect("det > 0"), wdet: det }))
            })
            .collect();
        Ok(Self { lengths, scale, viscous, penalty, mass, volume, check })
    }

    /// Compact 32×32 scalar mass matrix ∫ρ N_a N_b dV₀ (row-major). The full 96×96 mass
    /// matrix is this ⊗ I₃ (seed 000 eq. 9).
    pub fn mass_compact(&self, density: f64, tables: &ShapeTables) -> Vec<f64> {
        let mut m = vec![0.0; N_SHAPE * N_SHAPE];
        for (p, rp) in self.mass.iter().enumerate() {
            let n = &tables.mass.n[p];
            let w = density * rp.wdet;
            for a in 0..N_SHAPE {
                let na = w * n[a] * self.scale[a];
                for b in 0..N_SHAPE {
                    m[a * N_SHAPE + b] += na * n[b] * self.scale[b];
                }
            }
        }
        m
    }

    /// Compact 32×32 matrix H_ab = ∫ (g_a − ḡ_a)·(g_b − ḡ_b) dV₀ (row-major) over the
    /// viscous rule, with g_a = ∂(s_a N_a)/∂X and ḡ_a its element mean: F − F̄ = Σ_a e_a ⊗ (g_a − ḡ_a),
    /// so ∫ |F − F̄|² dV₀ = Σ_ab (e_a·e_b) H_ab. It vanishes on every affine deformation of the
    /// element (and on rigid motions, which are affine), and only there.
    pub fn non_affine_compact(&self, tables: &ShapeTables) -> Vec<f64> {
        let g: Vec<[[f64; 3]; N_SHAPE]> = self
            .viscous
            .iter()
            .enumerate()
            .map(|(p, rp)| {
                let b = shape_gradients(rp, &tables.viscous.dn[p]);
                std::array::from_fn(|a| b[a].map(|x| self.scale[a] * x))
            })
            .collect();
        let vol: f64 = self.viscous.iter().map(|rp| rp.wdet).sum();
        let mut mean = [[0.0; 3]; N_SHAPE];
        for (gp, rp) in g.iter().zip(&self.viscous) {
            for a in 0..N_SHAPE {
                for i in 0..3 {
                    mean[a][i] += rp.wdet * gp[a][i] / vol;
                }
            }
        }
        let mut h = vec![0.0; N_SHAPE * N_SHAPE];
        for (gp, rp) in g.iter().zip(&self.viscous) {
            let d: [[f64; 3]; N_SHAPE] = std::array::from_fn(|a| std::array::from_fn(|i| gp[a][i] - mean[a][i]));
            for a in 0..N_SHAPE {
                for b in 0..N_SHAPE {
                    h[a * N_SHAPE + b] += rp.wdet * (d[a][0] * d[b][0] + d[a][1] * d[b][1] + d[a][2] * d[b][2]);
                }
            }
        }
        h
    }

    /// ∫ρ N_a dV₀ for each compact column: the gravity force is this times g.
    pub fn gravity_scale(&self, density: f64, tables: &ShapeTables) -> [f64; N_SHAPE] {
        let mut g = [0.0; N_SHAPE];
        for (p, rp) in self.mass.iter().enumerate() {
            let n = &tables.mass.n[p];
            for a in 0..N_SHAPE {
                g[a] += density * rp.wdet * n[a] * self.scale[a];
            }
        }
        g
    }

    /// Current volume ∫ J dV₀ (evaluated with the viscous rule).
    pub fn volume_current(&self, e: &Compact, tables: &ShapeTables) -> f64 {
        let ehat = scaled(e, &self.scale);
        self.viscous
            .iter()
            .zip(&tables.viscous.dn)
            .map(|(rp, dn)| rp.wdet * (grad_xi(&ehat, dn) * rp.jinv).determinant())
            .sum()
    }

    /// Stored energy of the volumetric penalty, ∫ ½ k (J − 1)² dV₀ over the penalty rule
    /// (the potential whose gradient is the penalty part of the internal force).
    pub fn penalty_energy(&self, e: &Compact, tables: &ShapeTables, bulk_penalty: f64) -> f64 {
        let ehat = scaled(e, &self.scale);
        self.penalty
            .iter()
            .zip(&tables.penalty.dn)
            .map(|(rp, dn)| {
                let j = (grad_xi(&ehat, dn) * rp.jinv).determinant();
                0.5 * bulk_penalty * (j - 1.0) * (j - 1.0) * rp.wdet
            })
            .sum()
    }

    /// Stored energy of the shear stabilization, ∫ G_s dev(E):dev(E) dV₀ over the viscous rule
    /// (where its stress is evaluated, with the deviatoric one).
    pub fn stabilization_energy(&self, e: &Compact, tables: &ShapeTables, fluid: &Fluid) -> f64 {
        if fluid.shear_stabilization == 0.0 {
            return 0.0;
        }
        let ehat = scaled(e, &self.scale);
        self.viscous
            .iter()
            .zip(&tables.viscous.dn)
            .map(|(rp, dn)| fluid.stabilization_energy_density(&(grad_xi(&ehat, dn) * rp.jinv)) * rp.wdet)
            .sum()
    }

    /// Smallest and largest volume ratio J = det F over every point of the viscous,
    /// penalty and mass rules and the check points ([`ShapeTables::check`]), with the
    /// index of the point of the smallest (numbered viscous points first, then penalty,
    /// mass, then check points by their index in the check table). The mass and check
    /// points differ from the force points, so a field folding between those is seen. A rule
    /// of the same order as an earlier one has the same points and is skipped (its points keep
    /// their numbers): a strictly smaller J cannot be there.
    pub fn volume_ratio_range(&self, e: &Compact, tables: &ShapeTables) -> (f64, usize, f64) {
        self.volume_ratio_range_with(e, tables, true)
    }

    /// [`Self::volume_ratio_range`], skipping repeated rules or (`skip_repeated` false, the
    /// reference its tests compare with) not.
    #[doc(hidden)]
    pub fn volume_ratio_range_with(&self, e: &Compact, tables: &ShapeTables, skip_repeated: bool) -> (f64, usize, f64) {
        let ehat = scaled(e, &self.scale);
        let mut out = (f64::INFINITY, 0, f64::NEG_INFINITY);
        let o = tables.options;
        let rules = [
            (&self.viscous, &tables.viscous, false),
            (&self.penalty, &tables.penalty, skip_repeated && o.penalty == o.viscous),
            (&self.mass, &tables.mass, skip_repeated && (o.mass == o.viscous || o.mass == o.penalty)),
        ];
        let mut k = 0;
        for (pts, table, seen) in rules {
            if seen {
                k += pts.len();
                continue;
            }
            for (rp, dn) in pts.iter().zip(&table.dn) {
                let j = (grad_xi(&ehat, dn) * rp.jinv).determinant();
                if j.is_nan() || j < out.0 {
                    out.0 = j;
                    out.1 = k;
                }
                out.2 = out.2.max(j);
                k += 1;
            }
        }
        for (p, rp) in &self.check {
            let j = (grad_xi(&ehat, &tables.check.dn[*p]) * rp.jinv).determinant();
            if j.is_nan() || j < out.0 {
                out.0 = j;
                out.1 = k + p;
            }
            out.2 = out.2.max(j);
        }
        out
    }

    /// Internal force f = ∫ P : ∂F/∂e dV₀ of the element (compact, 96 entries
    /// `f[3a + i]`), and optionally the Jacobians K = ∂f/∂e and C = ∂f/∂ė (row-major
    /// 96×96). `index` is used in errors.
    ///
    /// With at least [`STRUCTURED_MIN_POINTS`] penalty points the Jacobian of the volumetric
    /// penalty uses its structure (see `VolumetricTangents`): about 3× fewer flops than the
    /// generic per-point 9×9 tangent path ([`VolumetricJacobian`]).
    pub fn internal_force(
        &self,
        index: usize,
        fluid: &Fluid,
        tables: &ShapeTables,
        e: &Compact,
        edot: &Compact,
        force: &mut [f64; N_COORDS],
        jac: Option<(&mut [f64], &mut [f64])>,
    ) -> Result<()> {
        // The structured path pays fixed costs (two 96×96 accumulations) that a 2×2×2 rule
        // does not recover (bench: 0.9× at 8 points, 1.15× at 27, 1.5× at 64).
        let path = if self.penalty.len() >= STRUCTURED_MIN_POINTS {
            VolumetricJacobian::Structured
        } else {
            VolumetricJacobian::Generic
        };
        self.internal_force_with(index, fluid, tables, (e, edot), force, jac, path)
    }

    /// [`ElementRef::internal_force`] with the volumetric Jacobian taken by the given path
    /// whatever the rule: the structured and generic paths are tested and benchmarked
    /// against each other.
    pub fn internal_force_with(
        &self,
        index: usize,
        fluid: &Fluid,
        tables: &ShapeTables,
        (e, edot): (&Compact, &Compact),
        force: &mut [f64; N_COORDS],
        jac: Option<(&mut [f64], &mut [f64])>,
        path: VolumetricJacobian,
    ) -> Result<()> {
        self.internal_force_paths(index, fluid, tables, (e, edot), force, jac, path, DeviatoricPath::Auto)
    }

    /// [`ElementRef::internal_force_with`] with, in addition, the kernel of the deviatoric
    /// stress chosen ([`DeviatoricPath`]; `Auto` takes the closed-form Newtonian kernel for an
    /// effectively Newtonian fluid): the kernels are tested and benchmarked against each other.
    pub fn internal_force_paths(
        &self,
        index: usize,
        fluid: &Fluid,
        tables: &ShapeTables,
        (e, edot): (&Compact, &Compact),
        force: &mut [f64; N_COORDS],
        mut jac: Option<(&mut [f64], &mut [f64])>,
        path: VolumetricJacobian,
        deviatoric_path: DeviatoricPath,
    ) -> Result<()> {
        let structured = path == VolumetricJacobian::Structured;
        force.fill(0.0);
        if let Some((k, c)) = jac.as_mut() {
            k.fill(0.0);
            c.fill(0.0);
        }
        let ehat = scaled(e, &self.scale);
        let edhat = scaled(edot, &self.scale);
        let mut tf: Tangent = [[0.0; 9]; 9];
        let mut tv: Tangent = [[0.0; 9]; 9];
        let want_t = jac.is_some();
        // Jacobian data collected over all points: B_p (32×3, column block p) and the
        // weighted tangents, so that the Jacobian is assembled with GEMMs afterwards.
        let npts = self.viscous.len() + self.penalty.len();
        let mut bcat = if want_t { Mat::<f64>::zeros(N_SHAPE, 3 * npts) } else { Mat::<f64>::zeros(0, 0) };
        let mut tangents: Vec<(Tangent, Tangent)> = Vec::with_capacity(if want_t { npts } else { 0 });
        let mut vol = if want_t && structured { Some(VolumetricTangents::new(self.penalty.len())) } else { None };
        let mut col = 0;
        for (pass, (pts, table)) in
            [(&self.viscous, &tables.viscous), (&self.penalty, &tables.penalty)].into_iter().enumerate()
        {
            let deviatoric = pass == 0;
            if !deviatoric && fluid.bulk_penalty == 0.0 && fluid.bulk_damping == 0.0 {
                continue;
            }
            for (p, (rp, dn)) in pts.iter().zip(&table.dn).enumerate() {
                let f = grad_xi(&ehat, dn) * rp.jinv;
                let fd = grad_xi(&edhat, dn) * rp.jinv;
                let bmat = shape_gradients(rp, dn);
                let pk = if deviatoric {
                    let t = if want_t { Some((&mut tf, &mut tv)) } else { None };
                    fluid.deviatoric_stress_with(&f, &fd, t, deviatoric_path).ok_or(AncfError::InvertedElement {
                        element: index,
                        point: p,
                        j: f.determinant(),
                    })?
                } else if let Some(vol) = vol.as_mut() {
                    vol.push(fluid, rp.wdet, &bmat, &f, &fd, &self.scale)
                } else {
                    let t = if want_t { Some((&mut tf, &mut tv)) } else { None };
                    fluid.volumetric_stress(&f, &fd, t).0
                };
                let ph = rp.wdet * pk;
                for a in 0..N_SHAPE {
                    let sa = self.scale[a];
                    for i in 0..3 {
                        force[3 * a + i] +=
                            sa * (ph[(i, 0)] * bmat[a][0] + ph[(i, 1)] * bmat[a][1] + ph[(i, 2)] * bmat[a][2]);
                    }
                }
                if want_t && (deviatoric || vol.is_none()) {
                    for a in 0..N_SHAPE {
                        for j in 0..3 {
                            bcat[(a, 3 * col + j)] = bmat[a][j];
                        }
                    }
                    let w = rp.wdet;
                    tangents.push((tf.map(|r| r.map(|x| w * x)), tv.map(|r| r.map(|x| w * x))));
                    col += 1;
                }
            }
        }
        if let Some((k, c)) = jac.as_mut() {
            assemble_tangents(k, c, &bcat, &tangents, &self.scale);
            if let Some(vol) = &vol {
                vol.assemble(k, c);
            }
        }
        if force.iter().any(|v| !v.is_finite()) {
            return Err(AncfError::NonFinite { what: "element internal force".into(), element: index });
        }
        Ok(())
    }
}

/// K[(a,i),(b,k)] = s_a s_b Σ_p Σ_{J,L} B_p[a,J] T_p[iJ][kL] B_p[b,L] (and C likewise),
/// assembled with one GEMM per component pair (i, k): [K_ik; C_ik] = [B·T^K_ik; B·T^C_ik]·Bᵀ,
/// where B·T_ik (32 × 3n_p) applies each point's 3×3 block T_p[i·][k·] to its B_p.
fn assemble_tangents(
    k: &mut [f64],
    c: &mut [f64],
    bcat: &Mat<f64>,
    tangents: &[(Tangent, Tangent)],
    scale: &[f64; N_SHAPE],
) {
    let np = tangents.len();
    if np == 0 {
        return;
    }
    // only the first 3·np columns are filled (a skipped penalty pass leaves the rest unused)
    let bcat_full = bcat;
    let bcat = bcat.as_ref().subcols(0, 3 * np);
    let mut bt = Mat::<f64>::zeros(2 * N_SHAPE, 3 * np);
    let mut out = Mat::<f64>::zeros(2 * N_SHAPE, N_SHAPE);
    for i in 0..3 {
        for kk in 0..3 {
            for (p, (tk, tc)) in tangents.iter().enumerate() {
                // the 3×3 blocks T_p[i·][k·] of both tangents, then column by column of B·T
                let blk = |t: &Tangent| {
                    let r = |j: usize| [t[3 * i + j][3 * kk], t[3 * i + j][3 * kk + 1], t[3 * i + j][3 * kk + 2]];
                    [r(0), r(1), r(2)]
                };
                let (bk, bc) = (blk(tk), blk(tc));
                let b0: &[f64; N_SHAPE] = bcat_full.col_as_slice(3 * p).try_into().unwrap();
                let b1: &[f64; N_SHAPE] = bcat_full.col_as_slice(3 * p + 1).try_into().unwrap();
                let b2: &[f64; N_SHAPE] = bcat_full.col_as_slice(3 * p + 2).try_into().unwrap();
                for l in 0..3 {
                    let col: &mut [f64; 2 * N_SHAPE] = bt.col_as_slice_mut(3 * p + l).try_into().unwrap();
                    let (ck, cc) = col.split_at_mut(N_SHAPE);
                    let (k0, k1, k2) = (bk[0][l], bk[1][l], bk[2][l]);
                    let (c0, c1, c2) = (bc[0][l], bc[1][l], bc[2][l]);
                    for a in 0..N_SHAPE {
                        ck[a] = b0[a] * k0 + b1[a] * k1 + b2[a] * k2;
                        cc[a] = b0[a] * c0 + b1[a] * c1 + b2[a] * c2;
                    }
                }
            }
            matmul(out.as_mut(), Accum::Replace, bt.as_ref(), bcat.transpose(), 1.0, Par::Seq);
            crate::clear_upper_simd();
            for a in 0..N_SHAPE {
                let row = (3 * a + i) * N_COORDS;
                for b in 0..N_SHAPE {
                    let s = scale[a] * scale[b];
                    k[row + 3 * b + kk] += s * out[(a, b)];
                    c[row + 3 * b + kk] += s * out[(N_SHAPE + a, b)];
                }
            }
        }
    }
}

/// The volumetric penalty's Jacobians from its structure. With P = p cof F,
/// p = k(J − 1) + c J̇, J̇ = cof F : Ḟ, and v_p = ∂J/∂e = Σ_J s_a B_aJ cof_iJ (a 96-vector
/// per point, compact index 3a + i), u_p = ∂J̇/∂e (the same with the mixed cofactor
/// ∂J̇/∂F = cof′(F)[Ḟ] in place of cof F):
///
/// - K = Σ_p w_p v_p (k v_p + c u_p)ᵀ + Σ_p w_p p_p ∂(cof F)/∂e, and C = Σ_p w_p c v_p v_pᵀ;
/// - the geometric term, with ∂cof_iJ/∂F_kK = ε_ikl ε_JKL F_lL, is
///   K_(a,i),(b,k) = s_a s_b Σ_l ε_ikl X_l[a,b], X_l = Σ_p w_p p_p B_p [−f_l]ₓ B_pᵀ
///   (f_l = row l of F, B_p the 32×3 matrix of B_a).
///
/// So the penalty points cost two 96×n_p×96 GEMMs and three 32×3n_p×32 GEMMs instead of
/// nine 64×3n_p×32 GEMMs plus a 9×9 tangent (18 cofactor derivatives) per point. The two
/// paths agree to round-off (`tests/element.rs`).
struct VolumetricTangents {
    /// v_p (columns), 96 × n_p.
    v: Mat<f64>,
    /// k w_p v_p + c w_p u_p (columns), 96 × n_p.
    w: Mat<f64>,
    /// c w_p v_p (columns), 96 × n_p.
    cv: Mat<f64>,
    /// B_p [−f_l]ₓ w_p p_p for l = 0, 1, 2 (32 × 3n_p each).
    y: [Mat<f64>; 3],
    /// s_a B_p (32 × 3n_p).
    b: Mat<f64>,
    /// Points pushed so far.
    n: usize,
}

impl VolumetricTangents {
    fn new(np: usize) -> Self {
        Self {
            v: Mat::zeros(N_COORDS, np),
            w: Mat::zeros(N_COORDS, np),
            cv: Mat::zeros(N_COORDS, np),
            y: [Mat::zeros(N_SHAPE, 3 * np), Mat::zeros(N_SHAPE, 3 * np), Mat::zeros(N_SHAPE, 3 * np)],
            b: Mat::zeros(N_SHAPE, 3 * np),
            n: 0,
        }
    }

    /// Adds a penalty point (weight `w`, shape gradients `bmat` = B_a) and returns its stress
    /// P = p cof F, computed as [`Fluid::volumetric_stress`] does (the same operations, so the
    /// forces of both Jacobian paths are identical).
    fn push(
        &mut self,
        fluid: &Fluid,
        w: f64,
        bmat: &[[f64; 3]; N_SHAPE],
        f: &M3,
        fd: &M3,
        scale: &[f64; N_SHAPE],
    ) -> M3 {
        let (k, c) = (fluid.bulk_penalty, fluid.bulk_damping);
        let cof = cofactor(f);
        let g = cofactor_derivative(f, fd); // ∂J̇/∂F
        let j = f.determinant();
        let p = k * (j - 1.0) + c * cof.component_mul(fd).sum();
        let n = self.n;
        // [−f_l]ₓ: (B × f_l) = −[f_l]ₓ B
        let cross = |l: usize| -> M3 {
            let (x, y, z) = (f[(l, 0)], f[(l, 1)], f[(l, 2)]);
            M3::new(0.0, z, -y, -z, 0.0, x, y, -x, 0.0)
        };
        let a_l = [cross(0) * (w * p), cross(1) * (w * p), cross(2) * (w * p)];
        for a in 0..N_SHAPE {
            let bv = Vector3::from(bmat[a]) * scale[a];
            let vb = cof * bv; // (Σ_J cof_iJ B_aJ)_i
            let ub = g * bv;
            for i in 0..3 {
                self.v[(3 * a + i, n)] = vb[i];
                self.w[(3 * a + i, n)] = w * (k * vb[i] + c * ub[i]);
                self.cv[(3 * a + i, n)] = w * c * vb[i];
                self.b[(a, 3 * n + i)] = bv[i];
            }
            for (l, al) in a_l.iter().enumerate() {
                let yb = al.transpose() * bv; // row a of B_p A_l
                for i in 0..3 {
                    self.y[l][(a, 3 * n + i)] = yb[i];
                }
            }
        }
        self.n += 1;
        p * cof
    }

    fn assemble(&self, k: &mut [f64], c: &mut [f64]) {
        let n = self.n;
        if n == 0 {
            return;
        }
        // Kᵀ = W Vᵀ (column-major): column r of Kᵀ is row r of the row-major K, so both
        // sides of the accumulation are contiguous. C = c V Vᵀ is symmetric.
        let mut out = Mat::<f64>::zeros(N_COORDS, N_COORDS);
        let v = self.v.as_ref().subcols(0, n);
        matmul(out.as_mut(), Accum::Replace, self.w.as_ref().subcols(0, n), v.transpose(), 1.0, Par::Seq);
        crate::clear_upper_simd();
        for (r, row) in k.chunks_exact_mut(N_COORDS).enumerate() {
            for (kk, x) in row.iter_mut().zip(out.col(r).iter()) {
                *kk += x;
            }
        }
        matmul(out.as_mut(), Accum::Replace, self.cv.as_ref().subcols(0, n), v.transpose(), 1.0, Par::Seq);
        crate::clear_upper_simd();
        for (r, row) in c.chunks_exact_mut(N_COORDS).enumerate() {
            for (cc, x) in row.iter_mut().zip(out.col(r).iter()) {
                *cc += x;
            }
        }
        let b = self.b.as_ref().subcols(0, 3 * n);
        let mut x = Mat::<f64>::zeros(N_SHAPE, N_SHAPE);
        // ε_ikl for (i, k) ≠: l = 3 − i − k, sign +1 for cyclic (i, k, l)
        for (l, y) in self.y.iter().enumerate() {
            matmul(x.as_mut(), Accum::Replace, y.as_ref().subcols(0, 3 * n), b.transpose(), 1.0, Par::Seq);
            crate::clear_upper_simd();
            let (i, kk) = ((l + 1) % 3, (l + 2) % 3); // ε_{i kk l} = +1
            for a in 0..N_SHAPE {
                for bb in 0..N_SHAPE {
                    let xv = x[(a, bb)];
                    k[(3 * a + i) * N_COORDS + 3 * bb + kk] += xv;
                    k[(3 * a + kk) * N_COORDS + 3 * bb + i] -= xv;
                }
            }
        }
    }
}

/// How [`ElementRef::internal_force_with`] forms the Jacobian of the volumetric penalty.
#[derive(Debug, Clone, Copy, PartialEq, Eq)]
pub enum VolumetricJacobian {
    /// From its structure: rank-one terms and the cofactor derivative (`VolumetricTangents`).
    Structured,
    /// From the 9×9 tangent ∂P/∂F of every penalty point, like the viscous stress.
    Generic,
}

/// Penalty points from which [`ElementRef::internal_force`] takes the structured
/// volumetric Jacobian (the 3×3×3 rule and above).
pub const STRUCTURED_MIN_POINTS: usize = 27;

/// Multiply compact columns by their slope scales.
#[inline]
pub fn scaled(e: &Compact, scale: &[f64; N_SHAPE]) -> Compact {
    let mut out = *e;
    for (o, s) in out.iter_mut().zip(scale) {
        o[0] *= s;
        o[1] *= s;
        o[2] *= s;
    }
    out
}

/// Convert a flat 96-vector `e[3a + i]` into compact form.
pub fn to_compact(e: &[f64]) -> Compact {
    let mut c = [[0.0; 3]; N_SHAPE];
    for a in 0..N_SHAPE {
        c[a] = [e[3 * a], e[3 * a + 1], e[3 * a + 2]];
    }
    c
}

/// Reference coordinates of a box element with corner `origin` and lengths `l`, undeformed.
pub fn box_element(origin: [f64; 3], l: [f64; 3]) -> Compact {
    let mut e = [[0.0; 3]; N_SHAPE];
    for (k, s) in crate::shape::NODE_SIGNS.iter().enumerate() {
        for i in 0..3 {
            e[4 * k][i] = origin[i] + (s[i] + 1.0) * 0.5 * l[i];
            e[4 * k + 1 + i][i] = 1.0;
        }
    }
    e
}
