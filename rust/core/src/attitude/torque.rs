//! External torques on the body, one implementation per physical effect.

use super::dual::{Dual, Real};

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
pub(crate) fn mat_vec<R: Real>(a: &[[R; 3]; 3], v: &[R; 3]) -> [R; 3] {
    std::array::from_fn(|i| a[i][0] * v[0] + a[i][1] * v[1] + a[i][2] * v[2])
}

#[inline(always)]
pub(crate) fn cross<R: Real>(a: &[R; 3], b: &[R; 3]) -> [R; 3] {
    [a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]]
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

    fn eval<R: Real>(&self, x: &TorqueInput<R>) -> [R; 3] {
        let mut t = [R::cst(0.0); 3];
        let centers = [(-x.mu, 1.0 - x.mu), (1.0 - x.mu, x.mu)];
        for (k, &(cx, gm)) in centers.iter().enumerate() {
            if !self.primaries[k] {
                continue;
            }
            let rs = [x.pos[0] - R::cst(cx), x.pos[1], x.pos[2]];
            let rb = mat_vec(&x.a, &rs);
            let r2 = rb[0] * rb[0] + rb[1] * rb[1] + rb[2] * rb[2];
            let r5 = r2 * r2 * r2.sqrt();
            let k3 = R::cst(3.0 * gm) / r5;
            let irb = [rb[0].scale(x.inertia[0]), rb[1].scale(x.inertia[1]), rb[2].scale(x.inertia[2])];
            let c = cross(&rb, &irb);
            for i in 0..3 {
                t[i] = t[i] + k3 * c[i];
            }
        }
        t
    }
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
