//! Bracketed roots of monotone scalar functions, one implementation each (issue 18):
//! [`bisect`] (a fixed number of halvings: the liquid depth of a fill, the rail head's tangent
//! angle) and [`illinois`], the Illinois variant of regula falsi (the Hertz ellipse's axis ratio,
//! the Kik–Piotrowski penetration carrying a force).

/// Where [`illinois`] stopped: the last point it evaluated and the final bracket.
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct Bracketed {
    /// The last point evaluated, with f(x) = 0 exactly when [`Self::exact`].
    pub x: f64,
    /// Whether f(x) was exactly 0.
    pub exact: bool,
    /// The lower end of the final bracket (f(lo) < 0).
    pub lo: f64,
    /// The upper end of the final bracket (f(hi) ≥ 0).
    pub hi: f64,
}

/// `steps` halvings of [lo, hi] keeping the half where the boundary lies: `right_of(mid)` says
/// whether it lies right of the midpoint (`lo = mid`) or not (`hi = mid`); returns the final
/// midpoint. For a function rising through a target, `right_of = |x| f(x) < target`.
pub fn bisect(mut lo: f64, mut hi: f64, steps: usize, mut right_of: impl FnMut(f64) -> bool) -> f64 {
    for _ in 0..steps {
        let mid = 0.5 * (lo + hi);
        if right_of(mid) {
            lo = mid;
        } else {
            hi = mid;
        }
    }
    0.5 * (lo + hi)
}

/// Illinois (modified regula falsi) on an increasing `f` bracketed by f(lo) = `flo` < 0 ≤
/// f(hi) = `fhi`: each step takes the secant point (the midpoint when that falls outside the
/// bracket) and halves the retained end's value when the same end is kept twice in a row. It
/// stops before a step once `done(lo, hi)`, when f is exactly 0, or after `max_steps` steps;
/// an error of `f` ends it with that error.
pub fn illinois<E>(
    mut f: impl FnMut(f64) -> Result<f64, E>,
    (mut lo, mut flo): (f64, f64),
    (mut hi, mut fhi): (f64, f64),
    done: impl Fn(f64, f64) -> bool,
    max_steps: usize,
) -> Result<Bracketed, E> {
    let mut x = 0.5 * (lo + hi);
    let mut side = 0i8;
    for _ in 0..max_steps {
        if done(lo, hi) {
            break;
        }
        x = (lo * fhi - hi * flo) / (fhi - flo);
        if !(x > lo && x < hi) {
            x = 0.5 * (lo + hi);
        }
        let fx = f(x)?;
        if fx == 0.0 {
            return Ok(Bracketed { x, exact: true, lo, hi });
        }
        if fx < 0.0 {
            lo = x;
            flo = fx;
            if side == -1 {
                fhi *= 0.5;
            }
            side = -1;
        } else {
            hi = x;
            fhi = fx;
            if side == 1 {
                flo *= 0.5;
            }
            side = 1;
        }
    }
    Ok(Bracketed { x, exact: false, lo, hi })
}

#[cfg(test)]
mod tests {
    use super::*;

    #[test]
    fn bisection_halves_the_bracket_toward_the_boundary() {
        // √2 on [0, 2] after 60 halvings (a bracket of 2^-59 m, below round-off)
        let x = bisect(0.0, 2.0, 60, |x| x * x < 2.0);
        assert!((x - 2f64.sqrt()).abs() <= 4.5e-16, "{x}");
        // zero halvings: the midpoint; a boundary outside the bracket: its end
        assert_eq!(bisect(0.0, 2.0, 0, |_| unreachable!()), 1.0);
        assert!((bisect(0.0, 2.0, 60, |_| true) - 2.0).abs() < 1e-15);
    }

    #[test]
    fn illinois_finds_a_root_superlinearly_and_stops_where_told() {
        // x³ − 2 on [0, 2]: the root 2^(1/3) to 1e-14 in fewer steps than bisection's 48
        let mut calls = 0;
        let f = |x: f64| -> Result<f64, ()> {
            calls += 1;
            Ok(x * x * x - 2.0)
        };
        let r = illinois(f, (0.0, -2.0), (2.0, 6.0), |lo, hi| hi - lo < 1e-14, 200).unwrap();
        assert!((r.x - 2f64.cbrt()).abs() < 1e-14, "{r:?}");
        assert!(r.lo <= 2f64.cbrt() && 2f64.cbrt() <= r.hi);
        assert!(calls < 20, "{calls} evaluations");
        // an exact zero ends it at that point
        let r = illinois(|x: f64| Ok::<_, ()>(x - 1.0), (0.0, -1.0), (2.0, 1.0), |_, _| false, 200).unwrap();
        assert_eq!((r.x, r.exact), (1.0, true));
        // an error of f ends it with that error
        let e = illinois(|_| Err::<f64, _>("no"), (0.0, -1.0), (2.0, 1.0), |_, _| false, 200);
        assert_eq!(e, Err("no"));
        // done before the first step: no evaluation, the midpoint
        let r = illinois(|_| -> Result<f64, ()> { panic!("evaluated") }, (0.0, -1.0), (2.0, 1.0), |_, _| true, 200);
        assert_eq!(r.unwrap().x, 1.0);
    }
}
