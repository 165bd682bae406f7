"""The graph calibration's residuals per motion pair, computed here from the factor definitions
(src/graph/factors.h, calibration_odometry.cpp) at a given estimate z = (x, y, scale, yaw).

Per pair i the graph has a free relative pose X_i (the robot's motion r_i^-1 r_{i+1}) tied to the
odometry's motion W by the odometry factor e_o = t2v(W^-1 X) with covariance S_o of W's (x, y,
theta), and to the mapped sensor motion M = T S_h(m) T^-1 by the sensor factor e_s = t2v(M^-1 X)
(weighted as G e_s with the sensor's information). Both errors are linear in X's coordinates, so
X is eliminated exactly: the pair's chi2 is d^T (S_o + S_m)^-1 d with d = coords(W) - coords(M)
(angle wrapped) and S_m the sensor covariance carried into the robot frame. Summed over the
pairs this is the solver's chi2 at its optimum for that z."""
from __future__ import annotations

from dataclasses import dataclass
from typing import Optional, Sequence

import numpy as np

from ._motion import wrap

CHI2_MEDIAN_3 = 2.365973884375338  # median of a chi2 with 3 degrees of freedom


def _rot3(theta: np.ndarray) -> np.ndarray:
    """(N, 3, 3) blockdiag(R(theta), 1)."""
    c, s = np.cos(theta), np.sin(theta)
    R = np.zeros((len(theta), 3, 3))
    R[:, 0, 0], R[:, 0, 1], R[:, 1, 0], R[:, 1, 1], R[:, 2, 2] = c, -s, s, c, 1.0
    return R


def sensor_to_robot(m: np.ndarray, z: Sequence[float]) -> np.ndarray:
    """T S_h(m) T^-1 for sensor motions m (N, 3) and z = (x, y, scale, yaw): (N, 3)."""
    x, y, h, yaw = z
    cp, sp = np.cos(m[:, 2]), np.sin(m[:, 2])
    cg, sg = np.cos(yaw), np.sin(yaw)
    rvx, rvy = cg * m[:, 0] - sg * m[:, 1], sg * m[:, 0] + cg * m[:, 1]
    return np.column_stack([(1 - cp) * x + sp * y + h * rvx, -sp * x + (1 - cp) * y + h * rvy, m[:, 2]])


def model_covariance(m: np.ndarray, relative: float, floor: float, sigma_theta: float) -> np.ndarray:
    """The options' default noise model of motions m (N, 3): diag(t2, t2, r2)."""
    t2 = floor ** 2 + (relative * np.hypot(m[:, 0], m[:, 1])) ** 2
    r2 = sigma_theta ** 2 + (relative * m[:, 2]) ** 2
    out = np.zeros((len(m), 3, 3))
    out[:, 0, 0], out[:, 1, 1], out[:, 2, 2] = t2, t2, r2
    return out


def component_covariance(m: np.ndarray, cov_right: np.ndarray) -> np.ndarray:
    """A covariance of the right perturbation of m as one of m's (x, y, theta): A C A^T."""
    A = _rot3(m[:, 2])
    return A @ cov_right @ np.transpose(A, (0, 2, 1))


def _noise_design(odometry: np.ndarray) -> np.ndarray:
    return np.column_stack([np.ones(len(odometry)), odometry[:, 0] ** 2 + odometry[:, 1] ** 2, odometry[:, 2] ** 2])


def _nonnegative_lstsq(M: np.ndarray, b: np.ndarray) -> np.ndarray:
    """min |M x - b| over x >= 0 for a few columns, as the library solves it: a column whose
    coefficient comes out negative is dropped and the rest solved again."""
    active = np.ones(M.shape[1], bool)
    for _ in range(M.shape[1]):
        x = np.zeros(M.shape[1])
        if not active.any():
            break
        x[active] = np.linalg.lstsq(M[:, active], b, rcond=None)[0]
        if not (x < 0).any():
            return x
        active &= x >= 0
    return np.zeros(M.shape[1])


def fit_odometry_noise(odometry: np.ndarray, residual: np.ndarray) -> np.ndarray:
    """Per component c of the residual: variance = a_c + b_c |t|^2 + g_c theta^2 fitted to the
    squared residuals by non-negative least squares, reweighted by 1/variance (the model of the
    library's estimate_odometry_noise). Returns the (3, 3) coefficients, row c = (a_c, b_c, g_c)."""
    A = _noise_design(odometry)
    scale = np.maximum(np.linalg.norm(A, axis=0), 1e-300)
    As = A / scale
    coefs = np.zeros((3, 3))
    for c in range(3):
        b = residual[:, c] ** 2
        w = np.ones(len(b))
        tiny = 1e-30 + 1e-6 * b.mean()
        for _ in range(6):
            coef = _nonnegative_lstsq(w[:, None] * As, w * b)
            w = 1.0 / np.maximum(As @ coef, tiny)
            w /= w.max()
        coefs[c] = coef / scale
    return coefs


def noise_covariance(coefs: np.ndarray, odometry: np.ndarray) -> np.ndarray:
    """The fitted model's (N, 3, 3) covariance of the right perturbation of each odometry motion,
    with the library's floors (1e-6 m, 1e-6 rad)."""
    var = np.maximum(_noise_design(odometry) @ coefs.T, 1e-12)
    out = np.zeros((len(odometry), 3, 3))
    out[:, [0, 1, 2], [0, 1, 2]] = var
    return out


@dataclass
class PairResiduals:
    """d (N, 3): odometry minus mapped sensor motion, robot frame at the interval's start (m, m,
    rad); cov (N, 3, 3) its covariance; chi2 (N,); normalised (N, 3): each component of d over
    its own standard deviation."""
    d: np.ndarray
    cov: np.ndarray
    chi2: np.ndarray
    normalised: np.ndarray


def pair_residuals(odometry: np.ndarray, sensor: np.ndarray, z: Sequence[float], odometry_cov: np.ndarray,
                   sensor_cov: np.ndarray) -> PairResiduals:
    """odometry, sensor: (N, 3) motions; *_cov: (N, 3, 3) covariances of their (x, y, theta)."""
    x, y, h, yaw = z
    M = sensor_to_robot(sensor, z)
    d = np.column_stack([odometry[:, :2] - M[:, :2], wrap(odometry[:, 2] - M[:, 2])])
    # G = diag(1/h, 1/h, 1) Ad(T)^-1 as the factor applies it; S_m = R G^-1 R^T S_s R G^-T R^T.
    cg, sg = np.cos(yaw), np.sin(yaw)
    Rt = np.array([[cg, sg], [-sg, cg]])
    G = np.eye(3)
    G[:2, :2] = Rt / h
    G[:2, 2] = np.array([[0.0, -1.0], [1.0, 0.0]]) @ Rt @ np.array([x, y]) / h
    Gi = np.linalg.inv(G)
    R = _rot3(M[:, 2])
    RT = np.transpose(R, (0, 2, 1))
    K = R @ Gi @ RT
    S = odometry_cov + K @ sensor_cov @ np.transpose(K, (0, 2, 1))
    chi2 = np.einsum("ni,ni->n", d, np.linalg.solve(S, d[:, :, None])[:, :, 0])
    normalised = d / np.sqrt(np.einsum("nii->ni", S))
    return PairResiduals(d, S, chi2, normalised)


def right_residual(odometry: np.ndarray, M: np.ndarray) -> np.ndarray:
    """t2v(W^-1 M): the right perturbation taking the odometry's motion to the mapped sensor's."""
    c, s = np.cos(odometry[:, 2]), np.sin(odometry[:, 2])
    dx, dy = M[:, 0] - odometry[:, 0], M[:, 1] - odometry[:, 1]
    return np.column_stack([c * dx + s * dy, -s * dx + c * dy, wrap(M[:, 2] - odometry[:, 2])])


def gated(chi2: np.ndarray, gate_sigma: float, inlier: Optional[np.ndarray] = None) -> np.ndarray:
    """Pairs beyond the calibration's gate: chi2 > gate^2 max(1, median(chi2 of inliers) / median
    of chi2(3)). An approximation of the library's gating, which is not reported per pair."""
    if gate_sigma <= 0:
        return np.zeros(len(chi2), bool)
    base = chi2 if inlier is None else chi2[inlier]
    k = max(1.0, float(np.median(base)) / CHI2_MEDIAN_3) if len(base) else 1.0
    return chi2 > gate_sigma ** 2 * k
