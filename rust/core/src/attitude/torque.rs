//! External torques on the body, one implementation per physical effect.

use super::dual::{Dual, Real};
use crate::scalar::{Arith, MulBy};

/// Dual numbers over the 13 coupled states (orbit 6, quaternion 4, rate 3).
pub type D13 = Dual<13>;

/// What a torque model sees at one instant: the synodic position and velocity, the attitude
/// matrix A (synodic -> body components, row-major), the inertial angular velocity in body
/// axes, the principal moments, the time and the mass parameter.
#[derive(Debug, Clone, Copy)]
pub struct TorqueInput<R> {
    pub t: f64,
    pub mu: f64,
    pub pos: [R; 3],
    pub vel: [R; 3],
    pub a: [[R; 3]; 3],
    pub w: [R; 3],
    pub inertia: [f64; 3],
}

/// A torque model (body axes, in the units of inertia / TU^2). Implementations provide the
/// value and the same formula over dual numbers, from which the variational equations get
/// the exact Jacobian; writing the formula once over [`Real`] gives both.
pub trait Torque: Send + Sync {
    fn name(&self) -> &'static str;
    fn torque(&self, x: &TorqueInput<f64>) -> [f64; 3];
    fn torque_dual(&self, x: &TorqueInput<D13>) -> [D13; 3];
}

#[inline(always)]
pub(crate) fn mat_vec<R: Arith>(a: &[[R; 3]; 3], v: &[R; 3]) -> [R; 3] {
    [dot3(&a[0], v), dot3(&a[1], v), dot3(&a[2], v)]
}

#[inline(always)]
pub(crate) fn dot3<R: Arith>(u: &[R; 3], v: &[R; 3]) -> R {
    // u0 v0 + u1 v1 + u2 v2, fused on the lanes of FMA levels ([`Arith::madd`])
    u[2].madd(v[2], u[1].madd(v[1], u[0] * v[0]))
}

#[inline(always)]
pub(crate) fn cross<R: Arith>(a: &[R; 3], b: &[R; 3]) -> [R; 3] {
    // a1 b2 - a2 b1, ..., fused on the lanes of FMA levels ([`Arith::madd`])
    [(-a[2]).madd(b[1], a[1] * b[2]), (-a[0]).madd(b[2], a[2] * b[0]), (-a[1]).madd(b[0], a[0] * b[1])]
}

/// Gravity gradient of both primaries (docs/physics.md, attitude):
/// T = 3 sum_i mu_i / r_i^5 (r_i x I r_i), r_i the position relative to primary i in body
/// axes, mu_1 = 1 - mu, mu_2 = mu. Either primary can be switched off (e.g. the two-body limit).
#[derive(Debug, Clone, Copy, PartialEq)]
pub struct GravityGradient {
    /// [larger primary (Earth), smaller primary (Moon)].
    pub primaries: [bool; 2],
}

impl GravityGradient {
    pub const BOTH: Self = Self { primaries: [true, true] };

    #[inline(always)]
    fn eval<R: Real>(&self, x: &TorqueInput<R>) -> [R; 3] {
        let m = tidal_tensor(x.mu, &x.pos, self.primaries);
        gravity_gradient_torque(&x.a, &m, &x.inertia)
    }
}

/// The tidal tensor of the primaries at the synodic position `pos`:
/// M = sum_i 3 mu_i / r_i^5 r_i r_i' (synodic axes, r_i from primary i, mu_1 = 1 - mu,
/// mu_2 = mu; `primaries` switches either off), as (xx, yy, zz, xy, xz, yz). The gravity-gradient
/// torque depends on the orbit only through M ([`gravity_gradient_torque`]); the 3-D map
/// tabulates it once per orbit ([`crate::integrate::forcing::TidalTable`]).
#[inline(always)]
pub fn tidal_tensor<R: Real>(mu: f64, pos: &[R; 3], primaries: [bool; 2]) -> [R; 6] {
    let mut m = [R::cst(0.0); 6];
    let centers = [(-mu, 1.0 - mu), (1.0 - mu, mu)];
    for (k, &(cx, gm)) in centers.iter().enumerate() {
        if !primaries[k] {
            continue;
        }
        let terms = tidal_term(gm, &[pos[0] - R::cst(cx), pos[1], pos[2]]);
        for i in 0..6 {
            m[i] = m[i] + terms[i];
        }
    }
    m
}

/// One attracting point mass's tidal tensor 3 gm / |r|^5 r r' at the position `r` relative to
/// it, as (xx, yy, zz, xy, xz, yz): the term [`tidal_tensor`] sums over the primaries and the
/// ephemeris model ([`crate::ephemeris::attitude`]) over Earth, Moon and Sun (gm in the units of
/// |r|^3 per time unit squared).
#[inline(always)]
pub fn tidal_term<R: Real>(gm: f64, r: &[R; 3]) -> [R; 6] {
    let r2 = r[0] * r[0] + r[1] * r[1] + r[2] * r[2];
    let r5 = r2 * r2 * r2.sqrt();
    let k3 = R::cst(3.0 * gm) / r5;
    let kr = [k3 * r[0], k3 * r[1], k3 * r[2]];
    [kr[0] * r[0], kr[1] * r[1], kr[2] * r[2], kr[0] * r[1], kr[0] * r[2], kr[1] * r[2]]
}

/// The gravity-gradient torque in body axes from the synodic tidal tensor `m` ([`tidal_tensor`])
/// and the attitude matrix `a` (synodic -> body): with N = A M A' (the tensor in body axes),
/// T = ((Iz - Iy) N_yz, (Ix - Iz) N_xz, (Iy - Ix) N_xy), i.e. sum_i 3 mu_i / r_i^5 (r_i x I r_i)
/// with r_i in body axes. `inertia` holds the principal moments: f64 for the scalar model (a
/// scaling), per-lane values for the SIMD lanes ([`MulBy`]).
#[inline(always)]
pub fn gravity_gradient_torque<R: Arith + MulBy<K>, K: Copy + std::ops::Sub<Output = K>>(a: &[[R; 3]; 3], m: &[R; 6], inertia: &[K; 3]) -> [R; 3] {
    let d = moment_differences(inertia);
    let [n_yz, n_xz, n_xy] = tidal_in_body(a, m);
    [n_yz.mul_by(d[0]), n_xz.mul_by(d[1]), n_xy.mul_by(d[2])]
}

/// The differences of principal moments the gravity-gradient torque scales by:
/// (Iz - Iy, Ix - Iz, Iy - Ix).
#[inline(always)]
fn moment_differences<K: Copy + std::ops::Sub<Output = K>>(inertia: &[K; 3]) -> [K; 3] {
    [inertia[2] - inertia[1], inertia[0] - inertia[2], inertia[1] - inertia[0]]
}

/// The off-diagonal components (N_yz, N_xz, N_xy) of the tidal tensor in body axes,
/// N = A M A', from the synodic tensor `m` ([`tidal_tensor`]) and the attitude matrix `a`.
#[inline(always)]
fn tidal_in_body<R: Arith>(a: &[[R; 3]; 3], m: &[R; 6]) -> [R; 3] {
    let [xx, yy, zz, xy, xz, yz] = *m;
    let full = [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]];
    let v1 = mat_vec(&full, &a[1]);
    let v2 = mat_vec(&full, &a[2]);
    [dot3(&a[1], &v2), dot3(&a[0], &v2), dot3(&a[0], &v1)]
}

/// The ratios ((Iz - Iy)/Ix, (Ix - Iz)/Iy, (Iy - Ix)/Iz) of [`gravity_gradient_euler_rate`].
#[inline(always)]
pub fn euler_ratios<K: Copy + std::ops::Sub<Output = K> + std::ops::Div<Output = K>>(inertia: &[K; 3]) -> [K; 3] {
    let d = moment_differences(inertia);
    [d[0] / inertia[0], d[1] / inertia[1], d[2] / inertia[2]]
}

/// Euler's equations under the gravity gradient alone ([`gravity_gradient_torque`] into
/// [`euler_rate`]) in the form the 3-D map's lanes integrate: the torque's and the gyroscopic
/// term's factors are the same difference of moments, Ix wdot_x = (Iz - Iy) (N_yz - wy wz) and
/// cyclically, so wdot = k (N_yz - wy wz, N_xz - wz wx, N_xy - wx wy) with the [`euler_ratios`] k.
#[inline(always)]
pub fn gravity_gradient_euler_rate<R: Arith + MulBy<K>, K: Copy>(a: &[[R; 3]; 3], m: &[R; 6], w: &[R; 3], k: &[K; 3]) -> [R; 3] {
    let [n_yz, n_xz, n_xy] = tidal_in_body(a, m);
    [(-w[1]).madd(w[2], n_yz).mul_by(k[0]), (-w[2]).madd(w[0], n_xz).mul_by(k[1]), (-w[0]).madd(w[1], n_xy).mul_by(k[2])]
}

/// Euler's equations, wdot = I^-1 (T - w x I w), with the moments `inertia` and their inverses
/// `inv` (as in [`gravity_gradient_torque`]).
#[inline(always)]
pub fn euler_rate<R: Arith + MulBy<K>, K: Copy>(torque: &[R; 3], w: &[R; 3], inertia: &[K; 3], inv: &[K; 3]) -> [R; 3] {
    let iw = [w[0].mul_by(inertia[0]), w[1].mul_by(inertia[1]), w[2].mul_by(inertia[2])];
    let gyro = cross(w, &iw);
    [(torque[0] - gyro[0]).mul_by(inv[0]), (torque[1] - gyro[1]).mul_by(inv[1]), (torque[2] - gyro[2]).mul_by(inv[2])]
}

impl Torque for GravityGradient {
    fn name(&self) -> &'static str {
        "gravity_gradient"
    }
    fn torque(&self, x: &TorqueInput<f64>) -> [f64; 3] {
        self.eval(x)
    }
    fn torque_dual(&self, x: &TorqueInput<D13>) -> [D13; 3] {
        self.eval(x)
    }
}

/// Torque models by name, for the bindings and configuration files: "gravity_gradient" (both
/// primaries), "gravity_gradient_earth" / "gravity_gradient_primary1" (the larger only),
/// "gravity_gradient_moon" / "gravity_gradient_primary2" (the smaller only).
pub fn gravity_gradient_by_name(name: &str) -> crate::error::Result<GravityGradient> {
    let primaries = match name {
        "gravity_gradient" => [true, true],
        "gravity_gradient_earth" | "gravity_gradient_primary1" => [true, false],
        "gravity_gradient_moon" | "gravity_gradient_primary2" => [false, true],
        _ => {
            return Err(crate::error::invalid(
                "torques",
                format!("unknown torque {name:?}; known: gravity_gradient, gravity_gradient_earth, gravity_gradient_moon"),
            ))
        }
    };
    Ok(GravityGradient { primaries })
}

#[cfg(test)]
mod tests {
    use super::*;
    use crate::attitude::{dcm_with, euler_rate, quat_kinematics};

    // Test references: the attitude laws as written before `Arith::madd` (products summed left to
    // right, the halving and doubling applied last), over any Arith type.
    fn dcm_before<R: Arith>(q: &[R; 4], one: R) -> [[R; 3]; 3] {
        let [q1, q2, q3, q4] = *q;
        let n = one / (q1 * q1 + q2 * q2 + q3 * q3 + q4 * q4);
        let (a, b, c, d) = (q1 * q1, q2 * q2, q3 * q3, q4 * q4);
        [
            [(a - b - c + d) * n, (q1 * q2 + q3 * q4).scale(2.0) * n, (q1 * q3 - q2 * q4).scale(2.0) * n],
            [(q1 * q2 - q3 * q4).scale(2.0) * n, (-a + b - c + d) * n, (q2 * q3 + q1 * q4).scale(2.0) * n],
            [(q1 * q3 + q2 * q4).scale(2.0) * n, (q2 * q3 - q1 * q4).scale(2.0) * n, (-a - b + c + d) * n],
        ]
    }
    fn kinematics_before<R: Arith>(q: &[R; 4], wr: &[R; 3]) -> [R; 4] {
        let [q1, q2, q3, q4] = *q;
        [
            (q4 * wr[0] - q3 * wr[1] + q2 * wr[2]).scale(0.5),
            (q3 * wr[0] + q4 * wr[1] - q1 * wr[2]).scale(0.5),
            (-q2 * wr[0] + q1 * wr[1] + q4 * wr[2]).scale(0.5),
            (-q1 * wr[0] - q2 * wr[1] - q3 * wr[2]).scale(0.5),
        ]
    }
    fn dot_before<R: Arith>(u: &[R; 3], v: &[R; 3]) -> R {
        u[0] * v[0] + u[1] * v[1] + u[2] * v[2]
    }
    fn torque_before<R: Arith + MulBy<f64>>(a: &[[R; 3]; 3], m: &[R; 6], inertia: &[f64; 3]) -> [R; 3] {
        let [xx, yy, zz, xy, xz, yz] = *m;
        let full = [[xx, xy, xz], [xy, yy, yz], [xz, yz, zz]];
        let mv = |v: &[R; 3]| [dot_before(&full[0], v), dot_before(&full[1], v), dot_before(&full[2], v)];
        let (v1, v2) = (mv(&a[1]), mv(&a[2]));
        let (n_xy, n_xz, n_yz) = (dot_before(&a[0], &v1), dot_before(&a[0], &v2), dot_before(&a[1], &v2));
        [n_yz.mul_by(inertia[2] - inertia[1]), n_xz.mul_by(inertia[0] - inertia[2]), n_xy.mul_by(inertia[1] - inertia[0])]
    }
    fn cross_before<R: Arith>(a: &[R; 3], b: &[R; 3]) -> [R; 3] {
        [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
    }

    /// Pseudo-random numbers in [-1, 1) (a fixed linear congruential sequence).
    fn uniform(seed: &mut u64) -> f64 {
        *seed = seed.wrapping_mul(6364136223846793005).wrapping_add(1442695040888963407);
        (*seed >> 11) as f64 / (1u64 << 52) as f64 - 1.0
    }

    fn bits<const N: usize>(x: &Dual<N>) -> Vec<u64> {
        std::iter::once(x.re).chain(x.eps).map(f64::to_bits).collect()
    }

    /// The scalar model (f64, and dual numbers for its STM) keeps its bits: the attitude
    /// matrix, the kinematics, the gravity-gradient torque and the gyroscopic term written with
    /// `Arith::madd` equal the former expressions exactly (addition commutes, negation and
    /// scaling by 2 or 1/2 are exact) on 2000 random attitudes, rates and tensors, each with
    /// derivatives in three directions. Reference: the former expressions above; tolerance:
    /// none (bit for bit).
    #[test]
    fn scalar_attitude_laws_keep_their_bits() {
        let mut seed = 7u64;
        let inertia = [0.8, 0.9, 1.0];
        for _ in 0..2000 {
            let mut r = || uniform(&mut seed);
            let dual = |x: f64, k: usize, s: f64| Dual::<3> { re: x, eps: std::array::from_fn(|j| if j == k { s } else { 0.0 }) };
            let q: [Dual<3>; 4] = std::array::from_fn(|i| dual(r(), i % 3, r()));
            let w: [Dual<3>; 3] = std::array::from_fn(|i| dual(3.0 * r(), (i + 1) % 3, r()));
            let m: [Dual<3>; 6] = std::array::from_fn(|i| dual(5.0 * r(), i % 3, r()));
            let one = Dual::<3> { re: 1.0, eps: [0.0; 3] };
            let (a, a0) = (dcm_with(&q, one), dcm_before(&q, one));
            for i in 0..3 {
                for j in 0..3 {
                    assert_eq!(bits(&a[i][j]), bits(&a0[i][j]), "A[{i}][{j}]");
                }
            }
            let pairs = [
                (quat_kinematics(&q, &w).to_vec(), kinematics_before(&q, &w).to_vec()),
                (gravity_gradient_torque(&a, &m, &inertia).to_vec(), torque_before(&a, &m, &inertia).to_vec()),
                (cross(&w, &m[..3].try_into().unwrap()).to_vec(), cross_before(&w, &m[..3].try_into().unwrap()).to_vec()),
            ];
            for (got, want) in pairs {
                for (g, e) in got.iter().zip(&want) {
                    assert_eq!(bits(g), bits(e));
                }
            }
            // f64 too (the scalar model's values)
            let qf = q.map(|x| x.re);
            let (af, af0) = (dcm_with(&qf, 1.0), dcm_before(&qf, 1.0));
            assert_eq!(af.map(|r| r.map(f64::to_bits)), af0.map(|r| r.map(f64::to_bits)));
        }
    }

    /// The lanes' form of Euler's equations under the gravity gradient
    /// (`gravity_gradient_euler_rate` with `euler_ratios`) against the torque into Euler's
    /// equations (`gravity_gradient_torque`, `euler_rate`), on 2000 random states and three
    /// bodies: the same equations (Ix wdot_x = (Iz - Iy)(N_yz - wy wz) and cyclically), to
    /// 1e-14 relative to the largest term. Reference: the analytic identity; tolerance: rounding.
    #[test]
    fn euler_ratio_form_equals_torque_then_euler() {
        let mut seed = 11u64;
        for inertia in [[0.8, 0.9, 1.0], [12.12e6, 89.68e6, 96.95e6], [1.0, 0.6, 0.7]] {
            let inv = inertia.map(|v| 1.0 / v);
            let k = euler_ratios(&inertia);
            for _ in 0..2000 {
                let mut r = || uniform(&mut seed);
                let q = [r(), r(), r(), r()];
                let w = [3.0 * r(), 3.0 * r(), 3.0 * r()];
                let m = [5.0 * r(), 5.0 * r(), 5.0 * r(), r(), r(), r()];
                let a = dcm_with(&q, 1.0);
                let got = gravity_gradient_euler_rate(&a, &m, &w, &k);
                let want = euler_rate(&gravity_gradient_torque(&a, &m, &inertia), &w, &inertia, &inv);
                let scale = 1.0 + w.iter().map(|v| v * v).sum::<f64>() + m.iter().map(|v| v.abs()).sum::<f64>();
                for i in 0..3 {
                    assert!((got[i] - want[i]).abs() <= 1e-14 * scale, "{inertia:?}, component {i}: {} vs {}", got[i], want[i]);
                }
            }
        }
    }
}
