//! The output warps of the optimizer: rank and tail transforms of the observed scores.

#[derive(Debug, Clone, PartialEq)]
pub(super) enum Warp {
    Tail(TailWarp),
    Rank(RankWarp),
}

impl Warp {
    pub(super) fn forward(&self, z: f64) -> f64 {
        match self {
            Warp::Tail(t) => t.forward(z),
            Warp::Rank(r) => r.forward(z),
        }
    }
    pub(super) fn inverse(&self, w: f64) -> f64 {
        match self {
            Warp::Tail(t) => t.inverse(w),
            Warp::Rank(r) => r.inverse(w),
        }
    }
    pub(super) fn slope_at_image(&self, w: f64) -> f64 {
        match self {
            Warp::Tail(t) => t.slope_at_image(w),
            Warp::Rank(r) => {
                let h = 1e-3;
                let dz = r.inverse(w + h) - r.inverse(w - h);
                if dz > 0.0 { 2.0 * h / dz } else { 1.0 }
            }
        }
    }
}

/// Piecewise-linear rank transform through the sorted distinct observations.
#[derive(Debug, Clone, PartialEq)]
pub(super) struct RankWarp {
    /// Sorted distinct values and their scores.
    z: Vec<f64>,
    w: Vec<f64>,
}

impl RankWarp {
    pub(super) fn fit(z: &[f64]) -> Option<Self> {
        let n = z.len();
        if n < 3 {
            return None;
        }
        let mut v = z.to_vec();
        v.sort_by(|a, b| a.total_cmp(b));
        let mut zs = Vec::new();
        let mut ws = Vec::new();
        let mut i = 0;
        while i < n {
            let mut j = i;
            while j + 1 < n && v[j + 1] == v[i] {
                j += 1;
            }
            zs.push(v[i]);
            ws.push(((i + j) as f64 / 2.0 + 0.5) / n as f64);
            i = j + 1;
        }
        if zs.len() < 2 {
            return None;
        }
        Some(RankWarp { z: zs, w: ws })
    }

    pub(super) fn interp(xs: &[f64], ys: &[f64], x: f64) -> f64 {
        let n = xs.len();
        if x <= xs[0] {
            let slope = (ys[1] - ys[0]) / (xs[1] - xs[0]);
            return ys[0] + slope * (x - xs[0]);
        }
        if x >= xs[n - 1] {
            let slope = (ys[n - 1] - ys[n - 2]) / (xs[n - 1] - xs[n - 2]);
            return ys[n - 1] + slope * (x - xs[n - 1]);
        }
        let k = xs.partition_point(|v| *v <= x).clamp(1, n - 1);
        let t = (x - xs[k - 1]) / (xs[k] - xs[k - 1]);
        ys[k - 1] + t * (ys[k] - ys[k - 1])
    }

    pub(super) fn forward(&self, z: f64) -> f64 {
        Self::interp(&self.z, &self.w, z)
    }

    pub(super) fn inverse(&self, w: f64) -> f64 {
        Self::interp(&self.w, &self.z, w)
    }
}

/// Monotone output warp that compresses the bad tail logarithmically (values below the
/// median `m` map to `m - s ln(1 + (m - z) / s)`), leaving the good half linear, so a few
/// huge bad values do not flatten the model where the optimum is.
#[derive(Debug, Clone, Copy, PartialEq)]
pub(super) struct TailWarp {
    m: f64,
    s: f64,
}

impl TailWarp {
    pub(super) fn fit(z: &[f64]) -> Option<Self> {
        if z.len() < 3 {
            return None;
        }
        let mut v = z.to_vec();
        v.sort_by(|a, b| a.total_cmp(b));
        let m = v[v.len() / 2];
        let top = v[v.len() - 1] - m;
        let mut dev: Vec<f64> = v.iter().map(|x| (x - m).abs()).collect();
        dev.sort_by(|a, b| a.total_cmp(b));
        let mad = dev[dev.len() / 2];
        let s = top.max(mad);
        if s > 0.0 && s.is_finite() {
            Some(TailWarp { m, s })
        } else {
            None
        }
    }

    pub(super) fn forward(&self, z: f64) -> f64 {
        if z >= self.m {
            z
        } else {
            self.m - self.s * ((self.m - z) / self.s).ln_1p()
        }
    }

    pub(super) fn inverse(&self, w: f64) -> f64 {
        if w >= self.m {
            w
        } else {
            self.m - self.s * ((self.m - w) / self.s).exp_m1()
        }
    }

    /// d forward / dz at the pre-image of `w`.
    pub(super) fn slope_at_image(&self, w: f64) -> f64 {
        if w >= self.m {
            1.0
        } else {
            (-(self.m - w) / self.s).exp()
        }
    }
}
