"""A task's symmetry from Python: the group and its transforms of observations and actions (rows
of arrays, e.g. for data augmentation), and the equivariance check of any callable policy."""
import numpy as np

from . import _masa


class EquivarianceError(AssertionError):
    """A policy is not equivariant under a symmetry (check_equivariance with raise_error)."""


def symmetry(task, overrides=None):
    """The symmetry (masa.Symmetry) of a catalog task, from its spec (configs/specs/)."""
    from .env import load_config
    return load_config(task, overrides).symmetry()


def check_equivariance(policy, sym, obs, tolerance=1e-4, raise_error=False):
    """How far policy(T_i o) is from T_i policy(o) over the group, on observations obs (B, obs_dim):
    max over i, rows and dimensions of |A(T_i o) - T_i A(o)| / (1 + |T_i A(o)|), the measure of
    masa's C++ check (common/model/equivariance_check.hpp). policy: a callable from (B, obs_dim)
    float32 to (B, act_dim), e.g. a masa.Policy or a wrapped torch module. Returns the worst error;
    raise_error: raise EquivarianceError when it exceeds tolerance."""
    obs = np.ascontiguousarray(obs, dtype=np.float32)
    if obs.ndim != 2 or obs.shape[1] != sym.obs_dim:
        raise ValueError(f"symmetry {sym.name}: observations have shape {obs.shape}, expected (N, {sym.obs_dim})")
    base = np.asarray(policy(obs), dtype=np.float64)
    if base.shape != (obs.shape[0], sym.act_dim):
        raise ValueError(f"symmetry {sym.name}: the policy gave actions of shape {base.shape}, "
                         f"expected ({obs.shape[0]}, {sym.act_dim})")
    worst = 0.0
    for i in range(1, sym.order):
        expected = sym.transform_act(base.astype(np.float32), i).astype(np.float64)
        got = np.asarray(policy(sym.transform_obs(obs, i)), dtype=np.float64)
        worst = max(worst, float(np.max(np.abs(got - expected) / (1.0 + np.abs(expected)))))
    if raise_error and not worst <= tolerance:
        raise EquivarianceError(f"symmetry {sym.name}: the policy is not equivariant (worst error {worst:.3g}, "
                                f"tolerance {tolerance:g})")
    return worst
