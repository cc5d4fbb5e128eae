//! CONTACT's patch rule (A_SEP, D_SEP, D_COMB; issue 21): whether neighbouring contact points
//! (local minima of the gap) form one patch or two, and the combined Kik–Piotrowski patch of two
//! points whose interpenetration regions lie close ([`PatchCombination`]; docs/validation.md,
//! "One patch or two").

use nalgebra::Vector3;

use super::{ContactGeometry, ContactPoint, WheelPose, WheelRailContact};
use crate::wheel_rail::ContactError;
use crate::wheel_rail::creep::{CreepForces, Creepages};
use crate::wheel_rail::hertz::HertzConstants;
use crate::wheel_rail::kik_piotrowski::{
    DEFAULT_EPSILON, DEFAULT_STRIPS, KpPatch, PatchModel, PatchSummary, SampledSeparation, SeparationFn,
};

/// The rigid interpenetration region of a contact point ([`WheelRailContact::interpenetration_region`]).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct InterpenetrationRegion {
    /// Ends along the contact's `e2` from the contact point, m (`lo ≤ 0 ≤ hi`).
    pub lateral: (f64, f64),
    /// The ends in the rail profile's plane `(v, z)` (`v` the profile's lateral coordinate, to
    /// the field side; `z` up), m, ordered by `v`: CONTACT's track y–z plane up to the rail's
    /// cant (a rotation), the same for both rails (mirror images give equal coordinates).
    pub ends: [(f64, f64); 2],
    /// Whether an end is the end of the sampled separation (the region may be wider).
    pub truncated: bool,
}

impl InterpenetrationRegion {
    /// CONTACT's `dist` between two regions: the distance in the rail profile's plane between
    /// their facing ends, 0 where they overlap (one region).
    pub fn distance(&self, other: &Self) -> f64 {
        let (lo, hi) = if self.ends[0].0 <= other.ends[0].0 { (self, other) } else { (other, self) };
        let (a, b) = (lo.ends[1], hi.ends[0]);
        if a.0 >= b.0 { 0.0 } else { (b.0 - a.0).hypot(b.1 - a.1) }
    }
}

/// How neighbouring contact points (local minima of the gap) form contact patches
/// ([`ContactSettings::patch_combination`]; docs/validation.md, "One patch or two").
#[derive(Debug, Clone, Copy, PartialEq, Default)]
pub enum PatchCombination {
    /// One patch per contact point (Hertz's ellipse or a Kik–Piotrowski patch), never combined:
    /// the default.
    #[default]
    Separate,
    /// CONTACT's rule (`A_SEP`, `D_SEP`, `D_COMB`; module `m_wr_locatecp`): two neighbouring
    /// loaded points whose rigid interpenetration regions ([`InterpenetrationRegion`]) lie within
    /// `d_sep` of each other (facing ends) and whose normals differ by at most `a_sep` form one
    /// Kik–Piotrowski patch over the union of their regions ([`KpPatch::combined`]); within
    /// `d_comb` fully, between `d_comb` and `d_sep` blended with the separate patches by the
    /// coupling weight `((d_sep − dist)/(d_sep − d_comb))^0.8` (1 at `d_comb`, 0 at `d_sep`).
    Contact {
        /// Largest angle between the two contact normals that may combine, rad, in (0, π].
        a_sep: f64,
        /// Largest distance between the regions' facing ends that may combine, m, > `d_comb`.
        d_sep: f64,
        /// Distance up to which the two are one patch, m, ≥ 0.
        d_comb: f64,
    },
}

/// Allowed range of `d_sep` and `d_comb`, m.
pub const PATCH_DISTANCE_RANGE: (f64, f64) = (0.0, 0.1);

impl PatchCombination {
    /// CONTACT's rule with its program defaults: A_SEP = π, D_SEP = 8 mm, D_COMB = 4 mm.
    pub fn contact() -> Self {
        Self::Contact { a_sep: std::f64::consts::PI, d_sep: 8e-3, d_comb: 4e-3 }
    }

    /// CONTACT's rule with the Manchester benchmark's input (`mbench_a22_left.inp`):
    /// A_SEP = 90°, D_SEP = 8 mm, D_COMB = 4 mm.
    pub fn manchester() -> Self {
        Self::Contact { a_sep: std::f64::consts::FRAC_PI_2, d_sep: 8e-3, d_comb: 4e-3 }
    }

    /// Checks the parameters (typed error naming the field and its allowed range).
    pub fn validate(&self) -> Result<(), ContactError> {
        if let Self::Contact { a_sep, d_sep, d_comb } = *self {
            let bad = |field: &str, value: f64, allowed: String| {
                ContactError::InvalidInput(ancf_core::error::invalid(field, value, &allowed).to_string())
            };
            let pi = std::f64::consts::PI;
            if !(a_sep.is_finite() && a_sep > 0.0 && a_sep <= pi) {
                return Err(bad("patch_combination.a_sep", a_sep, format!("an angle in (0, {pi}] rad")));
            }
            let (lo, hi) = PATCH_DISTANCE_RANGE;
            if !(d_comb.is_finite() && (lo..hi).contains(&d_comb)) {
                return Err(bad("patch_combination.d_comb", d_comb, format!("a distance in [{lo}, {hi}) m")));
            }
            if !(d_sep.is_finite() && d_sep > d_comb && d_sep <= hi) {
                return Err(bad(
                    "patch_combination.d_sep",
                    d_sep,
                    format!("a distance in (d_comb = {d_comb}, {hi}] m"),
                ));
            }
        }
        Ok(())
    }

    /// The coupling of two regions `dist` apart (m) whose normals differ by `angle` (rad): 0
    /// two patches, 1 one patch, in between CONTACT's weight of the separator.
    pub fn coupling(&self, dist: f64, angle: f64) -> f64 {
        match *self {
            Self::Separate => 0.0,
            Self::Contact { a_sep, d_sep, d_comb } => {
                if angle > a_sep || dist >= d_sep {
                    0.0
                } else if dist <= d_comb {
                    1.0
                } else {
                    ((d_sep - dist) / (d_sep - d_comb)).powf(0.8)
                }
            }
        }
    }
}

impl WheelRailContact {
    /// CONTACT's patch rule ([`PatchCombination::Contact`]) on the separate patches `out` of
    /// `geoms`: neighbouring loaded points (in the order of the wheel's lateral coordinate,
    /// taken in pairs from the first) whose regions couple with weight `c > 0`
    /// ([`PatchCombination::coupling`]) get one combined patch ([`Self::combined_patch`]); with
    /// `c = 1` it replaces their separate patches, with `0 < c < 1` the separate patches carry
    /// `1 − c` of their forces and the combined patch `c` of its own, so that the force is
    /// continuous where `dist` crosses `d_sep`.
    pub(super) fn combine_patches(
        &self,
        pose: &WheelPose,
        geoms: &[ContactGeometry],
        prescribed: Option<&Creepages>,
        out: &mut Vec<ContactPoint>,
    ) -> Result<(), ContactError> {
        let rule = self.settings.patch_combination;
        rule.validate()?;
        let loaded: Vec<ContactGeometry> = geoms.iter().filter(|g| g.penetration > 0.0).copied().collect();
        if loaded.len() < 2 {
            return Ok(());
        }
        let regions =
            loaded.iter().map(|g| self.region_and_separation(pose, g)).collect::<Result<Vec<_>, ContactError>>()?;
        let mut i = 0;
        while i + 1 < loaded.len() {
            let (a, b) = (loaded[i], loaded[i + 1]);
            let dist = regions[i].0.distance(&regions[i + 1].0);
            let angle = a.normal.dot(&b.normal).clamp(-1.0, 1.0).acos();
            let c = rule.coupling(dist, angle);
            if c <= 0.0 {
                i += 1;
                continue;
            }
            let combined = self.combined_patch(pose, [&a, &b], [&regions[i], &regions[i + 1]], prescribed)?;
            if c >= 1.0 {
                out.retain(|p| p.geometry != a && p.geometry != b);
                out.push(combined);
            } else {
                for p in out.iter_mut().filter(|p| p.geometry == a || p.geometry == b) {
                    *p = p.scaled(1.0 - c);
                }
                out.push(combined.scaled(c));
            }
            i += 2;
        }
        out.sort_by(|p, q| p.geometry.params[2].total_cmp(&q.geometry.params[2]));
        Ok(())
    }

    /// The combined patch of two loaded points `pair` with their regions and separations: a
    /// Kik–Piotrowski patch ([`KpPatch::combined`]; ε and strips of the patch model, the
    /// published ε = 0.55 and 60 strips with Hertz) over the union of the two regions, its
    /// normal force from the elastic approach held at both points weighted by their
    /// interpenetrations `W_k` (each point's rigid interpenetration area on its own side of the
    /// saddle of the separation between them). Its normal is turned about `e1` to the
    /// `W`-weighted mean of the two contact angles and its reference point is the `W`-weighted
    /// mean of the two points (CONTACT's reference angle and position); there the creepages are
    /// taken. The patch is computed in the frame of each point (its separation, its normal turned
    /// by the other's share of the angle) and the two results are averaged with the weights
    /// `W_k`, so that nothing changes discontinuously where the deeper point changes (the patch
    /// in the frame of the deeper point alone jumped by 13 % in the longitudinal force there).
    /// Friction: the `W`-weighted mean of the two points' μ. The point carries the surface
    /// parameters of the point with the larger weight and the larger penetration.
    fn combined_patch(
        &self,
        pose: &WheelPose,
        pair: [&ContactGeometry; 2],
        regions: [&(InterpenetrationRegion, SampledSeparation); 2],
        prescribed: Option<&Creepages>,
    ) -> Result<ContactPoint, ContactError> {
        let (epsilon, strips) = match self.patch_model {
            PatchModel::KikPiotrowski { epsilon, strips } => (epsilon, strips),
            PatchModel::Hertz => (DEFAULT_EPSILON, DEFAULT_STRIPS),
        };
        let at = |g: &ContactGeometry| 0.5 * (g.point_rail + g.point_wheel);
        let weight = |k: usize| {
            let (g, o) = (pair[k], pair[1 - k]);
            let (region, sep) = regions[k];
            part_weight(sep, g.penetration, region.lateral, (at(o) - at(g)).dot(&g.e2))
        };
        let (w0, w1) = (weight(0), weight(1));
        let total = w0 + w1;
        let w = [w0 / total, w1 / total];
        let mu = w[0] * self.friction_at(&pair[0].params) + w[1] * self.friction_at(&pair[1].params);
        let (e_star, g_mod, nu) = self.elastic_constants();
        let speed = pose.velocity.norm().max(self.settings.min_speed);
        // the patch in the frame of point d
        let in_frame =
            |d: usize| -> Result<(ContactGeometry, f64, f64, CreepForces, Creepages, KpPatch), ContactError> {
                let (gd, go, sep) = (pair[d], pair[1 - d], &regions[d].1);
                // the union of the regions along d's e2, from d's point
                let along = |k: usize, y: f64| (at(pair[k]) + pair[k].e2 * y - at(gd)).dot(&gd.e2);
                let mut span = (0.0f64, 0.0f64);
                for (k, region) in regions.iter().enumerate() {
                    let (lo, hi) = region.0.lateral;
                    for y in [along(k, lo), along(k, hi)] {
                        span = (span.0.min(y), span.1.max(y));
                    }
                }
                let y_o = along(1 - d, 0.0);
                let delta_o = (gd.penetration - sep.at(y_o).0).max(0.0);
                let approach = [(0.0, gd.penetration, w[d]), (y_o, delta_o, w[1 - d])];
                let mut patch = KpPatch::combined(sep, gd.penetration, epsilon, strips, e_star, span, &approach)?;
                // the reference angle and point: d's normal turned about e1 by the other's share of
                // the angle between the normals, the weighted mean of the points
                let turn = gd.normal.cross(&go.normal).dot(&gd.e1).atan2(gd.normal.dot(&go.normal));
                let phi = w[1 - d] * turn;
                let shift = w[1 - d] * y_o;
                let mut g = *gd;
                g.point_rail += gd.e2 * shift;
                g.point_wheel += gd.e2 * shift;
                g.normal = gd.normal * phi.cos() - gd.e2 * phi.sin();
                g.e2 = g.normal.cross(&g.e1);
                for s in &mut patch.strips {
                    s.y -= shift;
                }
                patch.lateral_extent = (patch.lateral_extent.0 - shift, patch.lateral_extent.1 - shift);
                patch.centroid -= shift;
                let v = pose.velocity + pose.angular_velocity.cross(&(at(&g) - pose.position));
                let pen_rate = -v.dot(&g.normal);
                let fn_ = (patch.normal_force * (1.0 + self.damping * pen_rate)).max(0.0);
                let patch = patch.scaled_to(fn_);
                let creepages = prescribed.copied().unwrap_or(Creepages {
                    longitudinal: v.dot(&g.e1) / speed,
                    lateral: v.dot(&g.e2) / speed,
                    spin: pose.angular_velocity.dot(&g.normal) / speed,
                });
                let creep = patch.creep(self.creep_model, &creepages, mu, g_mod, nu);
                Ok((g, pen_rate, fn_, creep, creepages, patch))
            };
        let (a, b) = (in_frame(0)?, in_frame(1)?);
        let mix = |x: f64, y: f64| w[0] * x + w[1] * y;
        let mix3 = |x: Vector3<f64>, y: Vector3<f64>| x * w[0] + y * w[1];
        let main = usize::from(w[1] > w[0] || (w[1] == w[0] && pair[1].penetration > pair[0].penetration));
        let mut g = if main == 0 { a.0 } else { b.0 };
        g.point_rail = mix3(a.0.point_rail, b.0.point_rail);
        g.point_wheel = mix3(a.0.point_wheel, b.0.point_wheel);
        g.normal = mix3(a.0.normal, b.0.normal).normalize();
        let e1 = mix3(a.0.e1, b.0.e1);
        g.e1 = (e1 - g.normal * e1.dot(&g.normal)).normalize();
        g.e2 = g.normal.cross(&g.e1);
        g.penetration = pair[0].penetration.max(pair[1].penetration);
        let kmin = self.settings.min_relative_curvature;
        let hertz = HertzConstants::new(g.curvature_x.max(kmin), g.curvature_y.max(kmin), e_star)?;
        let (pa, pb) = (a.5.summary(), b.5.summary());
        let summary = PatchSummary {
            lateral_extent: (
                mix(pa.lateral_extent.0, pb.lateral_extent.0),
                mix(pa.lateral_extent.1, pb.lateral_extent.1),
            ),
            max_half_length: mix(pa.max_half_length, pb.max_half_length),
            area: mix(pa.area, pb.area),
            centroid: mix(pa.centroid, pb.centroid),
            max_pressure: mix(pa.max_pressure, pb.max_pressure),
            truncated: pa.truncated || pb.truncated,
        };
        let (ea, eb) = (a.5.equivalent_ellipse(), b.5.equivalent_ellipse());
        Ok(ContactPoint {
            geometry: g,
            hertz,
            semi_axes: (mix(ea.0, eb.0), mix(ea.1, eb.1)),
            penetration_rate: mix(a.1, b.1),
            normal_force: mix(a.2, b.2),
            creepages: Creepages {
                longitudinal: mix(a.4.longitudinal, b.4.longitudinal),
                lateral: mix(a.4.lateral, b.4.lateral),
                spin: mix(a.4.spin, b.4.spin),
            },
            creep: CreepForces {
                longitudinal: mix(a.3.longitudinal, b.3.longitudinal),
                lateral: mix(a.3.lateral, b.3.lateral),
                spin_moment: mix(a.3.spin_moment, b.3.spin_moment),
            },
            patch: Some(summary),
        })
    }
}

/// The rigid interpenetration `∫ (d − h)₊ dy` of the region `lateral` of separation `s` on the
/// near side of the saddle towards `toward` (the other point's position along `y`): the region
/// is cut at the largest `h` between 0 and `toward`, which lies beyond the region while the two
/// regions are apart and splits the one region they form once they overlap (continuous as they
/// merge). Trapezoidal rule on the samples.
fn part_weight(s: &SampledSeparation, d: f64, lateral: (f64, f64), toward: f64) -> f64 {
    let (a, b) = if toward >= 0.0 { (0.0, toward) } else { (toward, 0.0) };
    let (mut saddle, mut h_max) = (toward, f64::NEG_INFINITY);
    for (&y, &h) in s.y.iter().zip(&s.h) {
        if y >= a && y <= b && h > h_max {
            (saddle, h_max) = (y, h);
        }
    }
    let (from, to) =
        if toward >= 0.0 { (lateral.0, saddle.min(lateral.1)) } else { (saddle.max(lateral.0), lateral.1) };
    let f = |k: usize| (d - s.h[k]).max(0.0);
    let mut sum = 0.0;
    for k in 1..s.y.len() {
        if s.y[k - 1] >= from && s.y[k] <= to {
            sum += 0.5 * (f(k - 1) + f(k)) * (s.y[k] - s.y[k - 1]);
        }
    }
    sum
}
