//! A short tour of `estimator_core::lie`: the conventions at work on SO(3) and SE(3), Example 5.2
//! of *Lie Groups and Smooth Manifolds for Robotic State Estimation*, and the Jacobians checked
//! against a finite difference, in f32 and f64.
//!
//! Run: `cargo run --release -p estimator-core --example lie_tour`

use estimator_core::lie::{skew, LieGroup, Se3, So3};
use nalgebra::{Vector3, Vector6};

fn main() {
    println!("estimator-core Lie-group tour (right perturbation: a ⊕ τ = a·exp(τ^))\n");

    // exp / log, near π included.
    let pi = core::f64::consts::PI;
    println!(
        "{:<28} {:>22} {:>12}",
        "rotation vector ω", "log(exp ω) − ω (max)", "angle"
    );
    for angle in [1e-9, 1e-4, 1.0, 3.0, pi - 1e-6] {
        let w = Vector3::new(0.6, 0.0, 0.8) * angle;
        let err = (So3::exp(&w).log() - w).amax();
        println!(
            "{:<28} {:>22.3e} {:>12.9}",
            format!("{:.3e}·[0.6,0,0.8]", angle),
            err,
            angle
        );
    }

    // The paper's Example 5.2: the Jacobian of f(R, p) = R p is F = R [[−p]× | I].
    let r = So3::exp(&Vector3::new(0.4, -0.9, 1.3));
    let p = Vector3::new(0.3, -1.7, 2.2);
    let (rp, j_r, j_p) = r.act_jac(&p);
    let closed = r.matrix() * skew(&-p);
    println!("\nExample 5.2: R p = {:.4?}", rp.as_slice());
    println!(
        "  ‖∂(Rp)/∂R − R[−p]×‖ = {:.1e}, ∂(Rp)/∂p = R: {}",
        (j_r - closed).amax(),
        j_p == r.matrix()
    );

    // A Jacobian against a central difference through ⊕ / ⊖ (the paper's Definition 4.6:
    // f(a ⊕ τ) ≈ f(a) + F τ).
    let a = Se3::exp(&Vector6::new(1.0, -2.0, 0.5, 0.3, -0.7, 1.1));
    let b = Se3::exp(&Vector6::new(-0.3, 0.7, 2.0, -1.2, 0.4, 0.25));
    let (ab, j_a, _) = a.compose_jac(&b);
    let h = 1e-6;
    let mut worst: f64 = 0.0;
    for i in 0..6 {
        let mut d = Vector6::zeros();
        d[i] = h;
        let col = (a.rplus(&d).compose(&b).rminus(&ab) - a.rplus(&-d).compose(&b).rminus(&ab))
            / (2.0 * h);
        worst = worst.max((col - j_a.column(i)).amax());
    }
    println!("\nSE(3) compose_jac ∂(ab)/∂a against a central difference: max error {worst:.1e}");

    // f32 agrees with f64 to a few ulps.
    let w32 = Vector3::new(0.3f32, -0.7, 1.1);
    let e32 = So3::exp(&w32).matrix().map(f64::from);
    let e64 = So3::exp(&w32.map(f64::from)).matrix();
    println!(
        "f32 exp against f64: max error {:.1e} (f32 ε = {:.1e})",
        (e32 - e64).amax(),
        f32::EPSILON
    );
    let t = a.interpolate(&b, 0.5);
    println!(
        "\ninterpolate(a, b, 0.5) translation = {:.4?}",
        t.translation().as_slice()
    );
}
