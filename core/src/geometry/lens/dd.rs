//! Double-double arithmetic (Dekker 1971; Shewchuk 1997): a value `hi + lo`
//! with about 106 significant bits, for the one place that needs it,
//! [`super::Lens::localize`].

/// A double-double value: `self.0 + self.1`, `|self.1|` at most half an
/// ulp of `self.0`.
#[derive(Clone, Copy, Debug)]
pub(super) struct Dd(pub(super) f64, pub(super) f64);

impl Dd {
    #[inline]
    pub(super) fn two_sum(a: f64, b: f64) -> Dd {
        let s = a + b;
        let bb = s - a;
        Dd(s, (a - (s - bb)) + (b - bb))
    }
    #[inline]
    pub(super) fn two_prod(a: f64, b: f64) -> Dd {
        let p = a * b;
        Dd(p, a.mul_add(b, -p))
    }
    #[inline]
    pub(super) fn norm(hi: f64, lo: f64) -> Dd {
        let s = hi + lo;
        Dd(s, lo - (s - hi))
    }
    #[inline]
    pub(super) fn add(self, o: Dd) -> Dd {
        let s = Dd::two_sum(self.0, o.0);
        Dd::norm(s.0, s.1 + self.1 + o.1)
    }
    #[inline]
    pub(super) fn mul_f(self, b: f64) -> Dd {
        let p = Dd::two_prod(self.0, b);
        Dd::norm(p.0, p.1 + self.1 * b)
    }
    #[inline]
    pub(super) fn div(self, o: Dd) -> Dd {
        let q1 = self.0 / o.0;
        let r = self.add(o.mul_f(-q1));
        let q2 = r.0 / o.0;
        Dd::norm(q1, q2)
    }
    #[inline]
    pub(super) fn value(self) -> f64 {
        self.0 + self.1
    }
}
