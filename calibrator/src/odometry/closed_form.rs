//! The paper's closed-form estimate (Censi et al. 2013, Sec. IV), the starting point of the
//! maximum-likelihood one.
//!
//! 1. The lidar turns as the robot does, so each interval's turn is linear in the wheels' speeds:
//!    `θ_k = J₂₁ Δφ_L + J₂₂ Δφ_R` (`Δφ` a wheel's turn over it, `T_k φ` in the paper) with `J₂₁ = −r_L / b`, `J₂₂ = r_R / b`: least squares.
//! 2. With the turn known, the robot's translation over an interval is `b · c_k` (`c_k` its arc
//!    for a unit wheel base), and `ℓ ⊕ s_k = r_k ⊕ ℓ` is linear in
//!    `x = (b, ℓ_x, ℓ_y, cos ℓ_θ, sin ℓ_θ)`: `L_k x = 0`. Minimise `Σ |L_k x|²` subject to
//!    `cos² + sin² = 1`. The paper solves it with a Lagrange multiplier (a quadratic in λ); here
//!    the three unconstrained unknowns are eliminated first (a Schur complement), which leaves
//!    the unit eigenvector of the smallest eigenvalue of a 2 × 2 matrix: the same minimum.

use nalgebra::{Matrix2, Matrix3, Matrix3x2, Matrix5, SMatrix, Vector2};

use super::interval::Interval;
use super::kinematics::{arc_factors, Geometry};
use crate::CalibrationError;

/// The closed-form geometry of `intervals`.
///
/// # Errors
/// [`CalibrationError::Unidentifiable`] when the drive does not turn, or turns so that the lidar's
/// position cannot be separated from the wheel base (a singular system).
pub fn closed_form(intervals: &[Interval]) -> Result<Geometry, CalibrationError> {
    let [j21, j22] = turn_gains(intervals)?;
    let mut m = Matrix5::<f64>::zeros();
    for t in intervals {
        // The robot's motion for a unit wheel base: each step's turn and translation.
        let (mut cx, mut cy, mut turn) = (0.0, 0.0, 0.0);
        for [left, right] in &t.wheel_turns_rad {
            let step_turn = j21 * left + j22 * right;
            let forward = (-j21 * left + j22 * right) / 2.0;
            let [along, across] = arc_factors(step_turn);
            let (sin, cos) = f64::sin_cos(turn);
            cx += forward * (cos * along - sin * across);
            cy += forward * (sin * along + cos * across);
            turn += step_turn;
        }
        let (sin, cos) = f64::sin_cos(turn);
        let [sx, sy, _] = t.lidar_motion;
        let l =
            SMatrix::<f64, 2, 5>::new(-cx, 1.0 - cos, sin, sx, -sy, -cy, -sin, 1.0 - cos, sy, sx);
        m += l.transpose() * l;
    }
    let a: Matrix3<f64> = m.fixed_view::<3, 3>(0, 0).into();
    let b: Matrix3x2<f64> = m.fixed_view::<3, 2>(0, 3).into();
    let d: Matrix2<f64> = m.fixed_view::<2, 2>(3, 3).into();
    let unidentifiable = || {
        CalibrationError::Unidentifiable(
            "the wheel base and the lidar's position cannot be told apart from this drive: \
             it must turn (both ways) and drive straight"
                .into(),
        )
    };
    let a_inv = a.try_inverse().ok_or_else(unidentifiable)?;
    let schur = d - b.transpose() * a_inv * b;
    let eigen = schur.symmetric_eigen();
    let smallest = if eigen.eigenvalues[0] <= eigen.eigenvalues[1] {
        0
    } else {
        1
    };
    let rotation: Vector2<f64> = eigen.eigenvectors.column(smallest).into();
    let mut unknowns = -(a_inv * b * rotation);
    let mut rotation = rotation;
    // The constraint fixes the rotation's length, not its sign: the wheel base is positive.
    if unknowns[0] < 0.0 {
        unknowns = -unknowns;
        rotation = -rotation;
    }
    let wheel_base_m = unknowns[0];
    let geometry = Geometry {
        left_radius_m: -j21 * wheel_base_m,
        right_radius_m: j22 * wheel_base_m,
        wheel_base_m,
        lidar: [unknowns[1], unknowns[2], rotation[1].atan2(rotation[0])],
    };
    if geometry.to_array().iter().all(|v| v.is_finite()) && wheel_base_m > 0.0 {
        Ok(geometry)
    } else {
        Err(unidentifiable())
    }
}

/// `J₂₁` and `J₂₂` of step 1.
fn turn_gains(intervals: &[Interval]) -> Result<[f64; 2], CalibrationError> {
    let (mut ata, mut aty) = (Matrix2::<f64>::zeros(), Vector2::<f64>::zeros());
    for t in intervals {
        let [left, right] = t.total_turns_rad();
        let row = Vector2::new(left, right);
        ata += row * row.transpose();
        aty += row * t.lidar_motion[2];
    }
    let gains = ata.try_inverse().map(|inv| inv * aty).ok_or_else(|| {
        CalibrationError::Unidentifiable(
            "the wheels never turned at different speeds: the drive must turn".into(),
        )
    })?;
    Ok([gains[0], gains[1]])
}
