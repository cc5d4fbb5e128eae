//! Constitutive models of the fluid: the viscous laws of seed 000 §3 and the
//! penalty incompressibility of §4.1, evaluated at one material point.
//!
//! Every model is written as a **first Piola–Kirchhoff stress** P(F, Ḟ), where F is
//! the deformation gradient with respect to the stress-free curved reference
//! configuration (seed 000: F = J = J_e J_0⁻¹) and Ḟ its rate. The element's generalized
//! internal force is then f = ∫ P : ∂F/∂e dV₀, which equals the seed's eq. (7)–(8) form
//! (P = F σ_P2 with σ_P2 = a J F⁻¹ D F⁻ᵀ, eq. 6). The tangents ∂P/∂F and ∂P/∂Ḟ are exact,
//! so the element Jacobians are exact too (checked against finite differences).
//!
//! # Viscous laws
//! With D = sym(Ḟ F⁻¹) the rate of deformation, the Cauchy stress is σ = 2η D, and
//! ‖D‖ = √(½ D:D) is the seed's norm (equal to γ̇/2 in simple shear, so that
//! σ₁₂ = τ₀ + μγ̇ for Bingham, exactly as in 1-D rheometry):
//!
//! | model | 2η(s), s = ‖D‖ | source |
//! |---|---|---|
//! | Newtonian | 2μ | §3.1 |
//! | Bingham | 2μ + τ₀/s | eq. (1) |
//! | Herschel–Bulkley | 2K(2s)^(n−1) + τ₀/s | eq. (2), see note |
//! | Casson | 2μ + 2√(2τ₀μ/s) + τ₀/s | eq. (4), see note |
//! | Oldroyd | Bingham when yielded, Hookean below the yield stress | eq. (3) |
//!
//! *Herschel–Bulkley.* We use the rheometer consistency K (Pa·sⁿ) with γ̇ = 2‖D‖, so that
//! simple shear gives τ = τ₀ + Kγ̇ⁿ. The seed writes 2μ‖D‖^(n−1); the two agree for
//! n = 1 and differ by the constant factor K = μ 2^(1−n) otherwise.
//!
//! *Casson.* Seed eq. (4) prints 2μ(1 + 2√(τ₀/‖D‖)), which is not dimensionally
//! consistent (μ·√(Pa·s)). We implement the standard Casson law √τ = √τ₀ + √(μγ̇), i.e.
//! τ = τ₀ + μγ̇ + 2√(τ₀μγ̇) in simple shear, which is what the printed form intends.
//!
//! # Regularization as ‖D‖ → 0
//! The yield-stress and power-law terms are singular at D = 0. We replace s by
//! s_ε = √(½ D:D + ε²) with ε = γ̇_ε/2, where γ̇_ε = [`Fluid::shear_rate_reg`]
//! (default 1e-2 s⁻¹). Then the apparent viscosity is bounded by μ + τ₀/γ̇_ε
//! (Bingham) and the stress is a smooth (C^∞) function of (F, Ḟ), as Newton needs.
//! As γ̇_ε → 0 the exact laws are recovered.
//!
//! # Oldroyd switching rule
//! Below the yield stress the Oldroyd fluid is a Hookean solid (seed eq. 3). We use the
//! deviatoric St-Venant–Kirchhoff stress S_e = 2G dev(E), E = ½(FᵀF − I), with shear
//! modulus G (the volumetric part is carried by the penalty). The branch is chosen by the
//! norm of this *elastic trial stress*: elastic when ‖S_e‖ < τ₀, Bingham when above. To keep
//! the residual differentiable the switch is blended with a C¹ smoothstep over
//! ‖S_e‖ ∈ [τ₀(1−w), τ₀(1+w)], w = [`Fluid::oldroyd_switch_width`] (default 0.05).
//! The default modulus is G = τ₀/γ_y with yield strain γ_y = 0.02 (gelled waxy crudes
//! yield at strains of order 10⁻²), i.e. G = 50 τ₀; pass your own with
//! [`Rheology::Oldroyd`]. Like the seed, the model is stateless: E is measured from the
//! element's stress-free reference, so a fluid that has flowed far is always in the
//! yielded (Bingham) branch. τ₀ = 0 gives the Newtonian fluid exactly.
//!
//! # Shear stabilization (zero-energy-mode control)
//! A liquid has no shear stiffness, and the discrete one inherits modes that the penalty and
//! the walls do not hold: linearized about the hydrostatic rest state, the hydrostatic
//! pre-stress gives some of them a small *negative* stiffness (the rest state of the default
//! discretization is unstable: `docs/validation.md`, "A stable rest state"). The optional
//! [`Fluid::shear_stabilization`] G_s (Pa) adds the deviatoric St-Venant–Kirchhoff stress
//! P_s = F 2G_s dev(E), E = ½(FᵀF − I), the same elastic law as the Oldroyd gel branch, with the
//! stored energy ∫ G_s dev(E):dev(E) dV₀ ([`Fluid::stabilization_energy_density`]). It is
//! objective (zero for rigid motions) and zero at the reference. With G_s a small fraction of
//! the hydrostatic pressure ρgH it removes the unstable rest modes of the rectangular and SwRI
//! tanks while moving the first sloshing frequency by about 2 G_s/(ρgH) (measured in
//! docs/validation.md); like the seed's Oldroyd gel, E is measured from the stress-free
//! reference, so its stress stays of order G_s · strain, far below ρgH in a sloshing liquid.
//! Zero (the default of [`Fluid::new`]) leaves the fluid exactly as before; runs opt in with
//! the recommended `rail_mbs::defaults::default_shear_stabilization`, because it also
//! stiffens the sloshing itself (measured in docs/validation.md, "A stable rest state").
//!
//! # Newtonian fast path
//! When 2η(s) is a constant and there is no elastic branch ([`Fluid::newtonian_two_eta`]:
//! Newtonian, and Bingham, Oldroyd, Casson with τ₀ = 0, Herschel–Bulkley with τ₀ = 0 and
//! n = 1), s and the regularization play no role and [`Fluid::deviatoric_stress`] takes the
//! closed-form kernel [`newtonian_stress`]: the same stress (bit-identical) and tangents
//! written entry by entry (equal to round-off, about 8× cheaper per point than the
//! generic directional derivatives; `benches/element.rs`). [`DeviatoricPath::Generic`]
//! forces the generic kernel for comparison.
//!
//! # Penalty incompressibility (seed 000 §4.1)
//! U_IC = ∫ ½ k_IC (J − 1)² dV₀ and the dissipation ∫ ½ c_TD J̇² dV₀ give
//! P_pen = [k_IC (J − 1) + c_TD J̇] ∂J/∂F, with ∂J/∂F = cof F = [f₂×f₃, f₃×f₁, f₁×f₂]
//! (columns f_j of F), and J̇ = cof F : Ḟ. Here k_IC is a bulk modulus (Pa) and c_TD a
//! bulk viscosity (Pa·s); the seed's per-element coefficients are k_IC·V₀ and c_TD·V₀
//! for a one-point rule.

use nalgebra::Matrix3;

use crate::error::{Result, check_non_negative, check_positive, check_range};

/// 3×3 matrix type used at material points.
pub type M3 = Matrix3<f64>;
/// Tangent ∂P/∂F (or ∂P/∂Ḟ) as a 9×9 array, index `3i + J` for P_iJ and F_iJ.
pub type Tangent = [[f64; 9]; 9];

/// Rheological law of the fluid (the deviatoric, rate-dependent part).
#[derive(Debug, Clone, Copy, PartialEq)]
pub enum Rheology {
    /// σ = 2μD.
    Newtonian {
        /// Dynamic viscosity μ (Pa·s).
        viscosity: f64,
    },
    /// σ = 2μD + τ₀ D/‖D‖ (seed eq. 1).
    Bingham {
        /// Plastic viscosity μ (Pa·s).
        viscosity: f64,
        /// Yield stress τ₀ (Pa).
        yield_stress: f64,
    },
    /// τ = τ₀ + Kγ̇ⁿ (seed eq. 2; see the module note on K).
    HerschelBulkley {
        /// Consistency K (Pa·sⁿ).
        consistency: f64,
        /// Power-law index n (> 0; < 1 shear thinning, > 1 shear thickening).
        power_index: f64,
        /// Yield stress τ₀ (Pa).
        yield_stress: f64,
    },
    /// Bingham above the yield stress, Hookean solid below (seed eq. 3).
    Oldroyd {
        /// Plastic viscosity μ (Pa·s).
        viscosity: f64,
        /// Yield stress τ₀ (Pa).
        yield_stress: f64,
        /// Shear modulus G of the unyielded gel (Pa); `None` uses G = 50 τ₀.
        elastic_modulus: Option<f64>,
    },
    /// √τ = √τ₀ + √(μγ̇) (seed eq. 4, dimensionally consistent form).
    Casson {
        /// Casson viscosity μ (Pa·s).
        viscosity: f64,
        /// Yield stress τ₀ (Pa).
        yield_stress: f64,
    },
}

impl Rheology {
    /// Check every parameter; errors name the field.
    pub fn validate(&self) -> Result<()> {
        match *self {
            Rheology::Newtonian { viscosity } => check_non_negative("viscosity", viscosity),
            Rheology::Bingham { viscosity, yield_stress } | Rheology::Casson { viscosity, yield_stress } => {
                check_non_negative("viscosity", viscosity)?;
                check_non_negative("yield_stress", yield_stress)
            }
            Rheology::HerschelBulkley { consistency, power_index, yield_stress } => {
                check_non_negative("consistency", consistency)?;
                check_range("power_index", power_index, 0.05, 3.0)?;
                check_non_negative("yield_stress", yield_stress)
            }
            Rheology::Oldroyd { viscosity, yield_stress, elastic_modulus } => {
                check_non_negative("viscosity", viscosity)?;
                check_non_negative("yield_stress", yield_stress)?;
                if let Some(g) = elastic_modulus {
                    check_positive("elastic_modulus", g)?;
                }
                Ok(())
            }
        }
    }

    /// Short name of the law.
    pub fn name(&self) -> &'static str {
        match self {
            Rheology::Newtonian { .. } => "newtonian",
            Rheology::Bingham { .. } => "bingham",
            Rheology::HerschelBulkley { .. } => "herschel-bulkley",
            Rheology::Oldroyd { .. } => "oldroyd",
            Rheology::Casson { .. } => "casson",
        }
    }

    /// Yield stress τ₀ (0 for Newtonian).
    pub fn yield_stress(&self) -> f64 {
        match *self {
            Rheology::Newtonian { .. } => 0.0,
            Rheology::Bingham { yield_stress, .. }
            | Rheology::HerschelBulkley { yield_stress, .. }
            | Rheology::Oldroyd { yield_stress, .. }
            | Rheology::Casson { yield_stress, .. } => yield_stress,
        }
    }

    /// The constant 2η when this law is effectively Newtonian, i.e. when [`Rheology::two_eta`]
    /// returns the same value and a zero derivative for every s > 0; `None` otherwise.
    ///
    /// Per law (read off `two_eta`): Newtonian always (2μ); Bingham, Oldroyd and Casson
    /// when τ₀ = 0 (the τ₀/s and √(τ₀μ/s) terms vanish, 2μ remains); Herschel–Bulkley when
    /// τ₀ = 0 and either n = 1 ((2s)⁰ = 1, so 2K) or K = 0 (2η ≡ 0). Any τ₀ > 0, or a
    /// power-law index n ≠ 1 with K > 0, makes 2η depend on s: not Newtonian. The
    /// regularization γ̇_ε only enters through s, so it plays no role in the constant cases.
    /// (The Oldroyd elastic branch exists only for τ₀ > 0, so it is excluded too; see
    /// [`Fluid::newtonian_two_eta`].)
    pub fn constant_two_eta(&self) -> Option<f64> {
        match *self {
            Rheology::Newtonian { viscosity } => Some(2.0 * viscosity),
            Rheology::Bingham { viscosity, yield_stress }
            | Rheology::Casson { viscosity, yield_stress }
            | Rheology::Oldroyd { viscosity, yield_stress, .. }
                if yield_stress == 0.0 =>
            {
                Some(2.0 * viscosity)
            }
            Rheology::HerschelBulkley { consistency, power_index, yield_stress }
                if yield_stress == 0.0 && (power_index == 1.0 || consistency == 0.0) =>
            {
                Some(2.0 * consistency)
            }
            _ => None,
        }
    }

    /// True when the law is effectively Newtonian (see [`Rheology::constant_two_eta`]).
    pub fn is_effectively_newtonian(&self) -> bool {
        self.constant_two_eta().is_some()
    }

    /// 2η(s) and its derivative with respect to s = ‖D‖ (regularized), for the viscous
    /// (yielded) branch.
    #[inline]
    pub fn two_eta(&self, s: f64) -> (f64, f64) {
        match *self {
            Rheology::Newtonian { viscosity } => (2.0 * viscosity, 0.0),
            Rheology::Bingham { viscosity, yield_stress } | Rheology::Oldroyd { viscosity, yield_stress, .. } => {
                (2.0 * viscosity + yield_stress / s, -yield_stress / (s * s))
            }
            Rheology::HerschelBulkley { consistency, power_index: n, yield_stress } => {
                let g = 2.0 * s;
                let pw = g.powf(n - 1.0);
                (
                    2.0 * consistency * pw + yield_stress / s,
                    4.0 * consistency * (n - 1.0) * pw / g - yield_stress / (s * s),
                )
            }
            Rheology::Casson { viscosity, yield_stress } => {
                let r = (2.0 * yield_stress * viscosity).sqrt();
                let rs = s.sqrt();
                (2.0 * viscosity + 2.0 * r / rs + yield_stress / s, -r / (s * rs) - yield_stress / (s * s))
            }
        }
    }
}

/// A fluid: density, rheology and penalty parameters.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Fluid {
    /// Mass density ρ in the reference configuration (kg/m³).
    pub density: f64,
    /// Viscous law.
    pub rheology: Rheology,
    /// Penalty bulk modulus k_IC (Pa) of U = ∫ ½ k (J−1)² dV₀.
    pub bulk_penalty: f64,
    /// Penalty bulk viscosity c_TD (Pa·s) of the dissipation ∫ ½ c J̇² dV₀.
    pub bulk_damping: f64,
    /// Regularization shear rate γ̇_ε (1/s) of the yield-stress and power-law terms.
    pub shear_rate_reg: f64,
    /// Relative half-width w of the Oldroyd elastic/viscous blend.
    pub oldroyd_switch_width: f64,
    /// Shear stabilization modulus G_s (Pa) of the zero-energy-mode control (module docs,
    /// "Shear stabilization"); 0 disables it.
    pub shear_stabilization: f64,
    /// Modulus G_h (Pa) of the non-affine-mode control: the stored energy
    /// ∫ G_h |F − F̄|² dV₀ per element, F̄ the element's mean deformation gradient
    /// (`FluidBody`, "Non-affine-mode control"); 0 disables it. Read when the body is built.
    pub hourglass_stabilization: f64,
}

impl Fluid {
    /// A fluid with the given density, rheology and penalty bulk modulus; the bulk damping
    /// defaults to zero and the regularization to γ̇_ε = 1e-2 s⁻¹, w = 0.05.
    pub fn new(density: f64, rheology: Rheology, bulk_penalty: f64) -> Result<Self> {
        let f = Fluid {
            density,
            rheology,
            bulk_penalty,
            bulk_damping: 0.0,
            shear_rate_reg: 1e-2,
            oldroyd_switch_width: 0.05,
            shear_stabilization: 0.0,
            hourglass_stabilization: 0.0,
        };
        f.validate()?;
        Ok(f)
    }

    /// Check every parameter; errors name the field and the allowed range.
    pub fn validate(&self) -> Result<()> {
        check_positive("density", self.density)?;
        self.rheology.validate()?;
        check_non_negative("bulk_penalty", self.bulk_penalty)?;
        check_non_negative("bulk_damping", self.bulk_damping)?;
        check_positive("shear_rate_reg", self.shear_rate_reg)?;
        check_range("oldroyd_switch_width", self.oldroyd_switch_width, 1e-4, 0.5)?;
        check_non_negative("shear_stabilization", self.shear_stabilization)?;
        check_non_negative("hourglass_stabilization", self.hourglass_stabilization)?;
        Ok(())
    }

    /// Shear modulus of the Oldroyd elastic branch (0 for other models).
    pub fn elastic_modulus(&self) -> f64 {
        match self.rheology {
            Rheology::Oldroyd { elastic_modulus: Some(g), .. } => g,
            Rheology::Oldroyd { yield_stress, .. } => 50.0 * yield_stress,
            _ => 0.0,
        }
    }

    /// True when the deviatoric stress depends on F alone through the Oldroyd elastic
    /// branch (i.e. the element has shear stiffness).
    pub fn has_elastic_branch(&self) -> bool {
        matches!(self.rheology, Rheology::Oldroyd { yield_stress, .. } if yield_stress > 0.0)
    }

    /// The constant 2η when the deviatoric stress of this fluid is exactly Newtonian,
    /// P = 2η J D F⁻ᵀ with 2η independent of s and no elastic branch: the law is effectively
    /// Newtonian ([`Rheology::constant_two_eta`]) and [`Fluid::has_elastic_branch`] is false.
    pub fn newtonian_two_eta(&self) -> Option<f64> {
        if self.has_elastic_branch() { None } else { self.rheology.constant_two_eta() }
    }

    /// True when [`Fluid::deviatoric_stress`] takes the closed-form Newtonian kernel
    /// ([`newtonian_stress`]).
    pub fn is_effectively_newtonian(&self) -> bool {
        self.newtonian_two_eta().is_some()
    }

    /// Deviatoric (viscous / Oldroyd) first Piola stress at a point, with optional
    /// tangents. Returns `None` if F is not invertible with positive determinant.
    ///
    /// An effectively Newtonian fluid ([`Fluid::newtonian_two_eta`]) takes the closed-form
    /// kernel [`newtonian_stress`]; every other fluid the generic one (9 directional
    /// derivatives). Both give the same stress and tangents to round-off
    /// (`tests/newtonian_fast_path.rs`).
    #[inline]
    pub fn deviatoric_stress(&self, f: &M3, fdot: &M3, tangents: Option<(&mut Tangent, &mut Tangent)>) -> Option<M3> {
        self.deviatoric_stress_with(f, fdot, tangents, DeviatoricPath::Auto)
    }

    /// [`Fluid::deviatoric_stress`] through the chosen kernel: the two kernels are tested and
    /// benchmarked against each other.
    #[inline]
    pub fn deviatoric_stress_with(
        &self,
        f: &M3,
        fdot: &M3,
        tangents: Option<(&mut Tangent, &mut Tangent)>,
        path: DeviatoricPath,
    ) -> Option<M3> {
        let gs = self.shear_stabilization;
        if gs == 0.0 {
            return self.rheology_stress(f, fdot, tangents, path);
        }
        let (p, tf) = match tangents {
            Some((tf, tv)) => (self.rheology_stress(f, fdot, Some((&mut *tf, tv)), path)?, Some(tf)),
            None => (self.rheology_stress(f, fdot, None, path)?, None),
        };
        let se = svk_deviatoric_stress(f, gs);
        if let Some(tf) = tf {
            for kl in 0..9 {
                let mut dx = M3::zeros();
                dx[(kl / 3, kl % 3)] = 1.0;
                let (_, dpe) = svk_deviatoric_derivative(f, &se, &dx, gs);
                for ij in 0..9 {
                    tf[ij][kl] += dpe[(ij / 3, ij % 3)];
                }
            }
        }
        Some(p + f * se)
    }

    /// The stress of the rheological law alone (without the shear stabilization), by the
    /// chosen kernel.
    #[inline]
    fn rheology_stress(
        &self,
        f: &M3,
        fdot: &M3,
        tangents: Option<(&mut Tangent, &mut Tangent)>,
        path: DeviatoricPath,
    ) -> Option<M3> {
        match (path, self.newtonian_two_eta()) {
            (DeviatoricPath::Auto, Some(two_eta)) => newtonian_stress(two_eta, f, fdot, tangents),
            _ => self.deviatoric_stress_generic(f, fdot, tangents),
        }
    }

    /// Stored energy density G_s dev(E):dev(E) (J/m³ of reference volume) of the shear
    /// stabilization, whose derivative with respect to F is its stress F 2G_s dev(E).
    pub fn stabilization_energy_density(&self, f: &M3) -> f64 {
        let de = dev(&(0.5 * (f.transpose() * f - M3::identity())));
        self.shear_stabilization * de.component_mul(&de).sum()
    }

    /// The generic kernel: any law, tangents by directional derivatives.
    fn deviatoric_stress_generic(
        &self,
        f: &M3,
        fdot: &M3,
        tangents: Option<(&mut Tangent, &mut Tangent)>,
    ) -> Option<M3> {
        let j = f.determinant();
        if !(j > 0.0) {
            return None;
        }
        let g = f.try_inverse()?;
        let eps = 0.5 * self.shear_rate_reg;
        let eps2 = eps * eps;
        let l = fdot * g;
        let d = 0.5 * (l + l.transpose());
        let s = (0.5 * d.component_mul(&d).sum() + eps2).sqrt();
        let (a, da) = self.rheology.two_eta(s);
        let gt = g.transpose();
        let pb = (a * j) * d * gt;

        let elastic = if self.has_elastic_branch() {
            let tau0 = self.rheology.yield_stress();
            let gmod = self.elastic_modulus();
            let se = svk_deviatoric_stress(f, gmod);
            let ne = (0.5 * se.component_mul(&se).sum()).sqrt();
            let w = self.oldroyd_switch_width;
            let t = (ne - tau0 * (1.0 - w)) / (2.0 * w * tau0);
            let (phi, dphi) = smoothstep(t);
            Some((se, ne, phi, dphi / (2.0 * w * tau0), gmod))
        } else {
            None
        };
        let p = match elastic {
            Some((se, _, phi, _, _)) => (1.0 - phi) * (f * se) + phi * pb,
            None => pb,
        };

        if let Some((tf, tv)) = tangents {
            // Directional derivatives along the 9 basis directions of F and of Ḟ.
            for kl in 0..9 {
                let mut dx = M3::zeros();
                dx[(kl / 3, kl % 3)] = 1.0;
                // --- derivative w.r.t. F ---
                let dg = -(g * dx * g);
                let dl = fdot * dg;
                let dd = 0.5 * (dl + dl.transpose());
                let ds = d.component_mul(&dd).sum() / (2.0 * s);
                let dj = j * (g * dx).trace();
                let dpb = (da * ds * j + a * dj) * d * gt + (a * j) * (dd * gt + d * dg.transpose());
                let dp_f = match elastic {
                    Some((se, ne, phi, dphi, gmod)) => {
                        let (dse, dpe) = svk_deviatoric_derivative(f, &se, &dx, gmod);
                        let dne = if ne > 0.0 { se.component_mul(&dse).sum() / (2.0 * ne) } else { 0.0 };
                        (1.0 - phi) * dpe + phi * dpb + (dphi * dne) * (pb - f * se)
                    }
                    None => dpb,
                };
                // --- derivative w.r.t. Ḟ ---
                let dl = dx * g;
                let dd = 0.5 * (dl + dl.transpose());
                let ds = d.component_mul(&dd).sum() / (2.0 * s);
                let dpb_v = (da * ds * j) * d * gt + (a * j) * dd * gt;
                let dp_v = match elastic {
                    Some((_, _, phi, _, _)) => phi * dpb_v,
                    None => dpb_v,
                };
                for ij in 0..9 {
                    tf[ij][kl] = dp_f[(ij / 3, ij % 3)];
                    tv[ij][kl] = dp_v[(ij / 3, ij % 3)];
                }
            }
        }
        Some(p)
    }

    /// Penalty (volumetric) first Piola stress P = [k(J−1) + cJ̇] cof F, with optional
    /// tangents. Also returns J. Valid for any F (no inverse needed).
    pub fn volumetric_stress(&self, f: &M3, fdot: &M3, tangents: Option<(&mut Tangent, &mut Tangent)>) -> (M3, f64) {
        let k = self.bulk_penalty;
        let c = self.bulk_damping;
        let cof = cofactor(f);
        let j = f.determinant();
        let jdot = cof.component_mul(fdot).sum();
        let p = k * (j - 1.0) + c * jdot;
        if let Some((tf, tv)) = tangents {
            for kl in 0..9 {
                let mut dx = M3::zeros();
                dx[(kl / 3, kl % 3)] = 1.0;
                let dcof = cofactor_derivative(f, &dx);
                let dj = cof.component_mul(&dx).sum();
                let djdot = dcof.component_mul(fdot).sum();
                let dp_f = (k * dj + c * djdot) * cof + p * dcof;
                let dp_v = (c * dj) * cof; // ∂J̇/∂Ḟ = cof F
                for ij in 0..9 {
                    tf[ij][kl] = dp_f[(ij / 3, ij % 3)];
                    tv[ij][kl] = dp_v[(ij / 3, ij % 3)];
                }
            }
        }
        (p * cof, j)
    }
}

/// Which kernel [`Fluid::deviatoric_stress_with`] uses.
#[derive(Debug, Clone, Copy, PartialEq, Eq, Default)]
pub enum DeviatoricPath {
    /// The closed-form Newtonian kernel when the fluid is effectively Newtonian, the generic
    /// one otherwise (what [`Fluid::deviatoric_stress`] does).
    #[default]
    Auto,
    /// Always the generic kernel (for tests and benchmarks).
    Generic,
}

/// Newtonian first Piola stress P = 2η J D Gᵀ (G = F⁻¹, L = Ḟ G, D = sym L, J = det F) with
/// a constant `two_eta` = 2η, and optionally its tangents in closed form. Returns `None` if
/// F is not invertible with positive determinant.
///
/// With c = 2ηJ, the derivatives along dF and dḞ are (dJ = J tr(G dF), dG = −G dF G):
///
/// - ∂P/∂F[dF] = c [tr(G dF) D Gᵀ − sym(L dF G) Gᵀ − D (G dF G)ᵀ],
/// - ∂P/∂Ḟ[dḞ] = c sym(dḞ G) Gᵀ.
///
/// Taking dF = e_k e_Lᵀ and writing A = c D Gᵀ (= P), H = G Gᵀ and M = G L:
///
/// - ∂P_iJ/∂F_kL = G_Lk A_iJ − G_Jk A_iL − ½c (L_ik H_LJ + G_Li M_Jk),
/// - ∂P_iJ/∂Ḟ_kL = ½c (δ_ik H_LJ + G_Li G_Jk),
///
/// 81 entries each from products precomputed once (three 3×3 products per point instead
/// of about a hundred in the generic kernel).
pub fn newtonian_stress(two_eta: f64, f: &M3, fdot: &M3, tangents: Option<(&mut Tangent, &mut Tangent)>) -> Option<M3> {
    let j = f.determinant();
    if !(j > 0.0) {
        return None;
    }
    let g = f.try_inverse()?;
    let l = fdot * g;
    let d = 0.5 * (l + l.transpose());
    let gt = g.transpose();
    // the same operations as the generic kernel, so both give bit-identical stresses
    let p = (two_eta * j) * d * gt;
    if let Some((tf, tv)) = tangents {
        let hc = 0.5 * two_eta * j;
        let arr = |m: &M3| -> [[f64; 3]; 3] {
            [[m[(0, 0)], m[(0, 1)], m[(0, 2)]], [m[(1, 0)], m[(1, 1)], m[(1, 2)]], [m[(2, 0)], m[(2, 1)], m[(2, 2)]]]
        };
        let a = arr(&p);
        let gg = arr(&g);
        let h = g * gt;
        let lm = arr(&(hc * l));
        let hm = arr(&h);
        let mm = arr(&(g * l));
        let gc = arr(&(hc * g));
        let hcm = arr(&(hc * h));
        for i in 0..3 {
            for jj in 0..3 {
                let (rf, rv) = (&mut tf[3 * i + jj], &mut tv[3 * i + jj]);
                for k in 0..3 {
                    let (lik, gjk, mjk) = (lm[i][k], gg[jj][k], mm[jj][k]);
                    let delta = if i == k { 1.0 } else { 0.0 };
                    for ll in 0..3 {
                        rf[3 * k + ll] = gg[ll][k] * a[i][jj] - gjk * a[i][ll] - lik * hm[ll][jj] - gc[ll][i] * mjk;
                        rv[3 * k + ll] = gc[ll][i] * gjk + delta * hcm[ll][jj];
                    }
                }
            }
        }
    }
    Some(p)
}

/// Deviatoric part of a 3×3 matrix.
#[inline]
pub fn dev(m: &M3) -> M3 {
    m - M3::identity() * (m.trace() / 3.0)
}

/// Second Piola stress S_e = 2G dev(E), E = ½(FᵀF − I), of the deviatoric St-Venant–Kirchhoff
/// law (the Oldroyd gel branch and the shear stabilization); its first Piola stress is F S_e.
#[inline]
pub fn svk_deviatoric_stress(f: &M3, g: f64) -> M3 {
    2.0 * g * dev(&(0.5 * (f.transpose() * f - M3::identity())))
}

/// The derivatives of [`svk_deviatoric_stress`] S_e and of F S_e along dF: (dS_e, d(F S_e)).
#[inline]
pub fn svk_deviatoric_derivative(f: &M3, se: &M3, dx: &M3, g: f64) -> (M3, M3) {
    let de = 0.5 * (f.transpose() * dx + dx.transpose() * f);
    let dse = 2.0 * g * dev(&de);
    (dse, dx * se + f * dse)
}

/// Cofactor matrix ∂(det F)/∂F = [f₂×f₃, f₃×f₁, f₁×f₂] (columns).
#[inline]
pub fn cofactor(f: &M3) -> M3 {
    let (c0, c1, c2) = (f.column(0), f.column(1), f.column(2));
    M3::from_columns(&[c1.cross(&c2), c2.cross(&c0), c0.cross(&c1)])
}

/// Directional derivative of the cofactor matrix along `df`.
#[inline]
pub fn cofactor_derivative(f: &M3, df: &M3) -> M3 {
    let (c0, c1, c2) = (f.column(0), f.column(1), f.column(2));
    let (d0, d1, d2) = (df.column(0), df.column(1), df.column(2));
    M3::from_columns(&[d1.cross(&c2) + c1.cross(&d2), d2.cross(&c0) + c2.cross(&d0), d0.cross(&c1) + c0.cross(&d1)])
}

/// C¹ smoothstep 3t² − 2t³ clamped to [0, 1], and its derivative.
#[inline]
pub fn smoothstep(t: f64) -> (f64, f64) {
    if t <= 0.0 {
        (0.0, 0.0)
    } else if t >= 1.0 {
        (1.0, 0.0)
    } else {
        (t * t * (3.0 - 2.0 * t), 6.0 * t * (1.0 - t))
    }
}
