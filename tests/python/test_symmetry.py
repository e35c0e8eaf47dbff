"""A task's transforms through the module are its spec's: read the spec's YAML here (PyYAML, not
masa's parser) and check every one-dimensional entry against its kind (invariant: +1 on the same
slot; odd under a mirror: -1; the limbs permuted by one shift of the group), that T_i = T_1^i is
orthogonal, and that transforming rows equals multiplying by the matrix. Then the equivariance
check of a callable: a shipped MASA policy and a fresh MASA model pass it, a fresh SA model (no
symmetry built in) fails it."""
import os
import re

import numpy as np
import yaml

import masa
from masa_test_util import run

SOURCE = os.path.dirname(masa._masa.configs_dir())
SPEC_TASKS = ["a1_beam", "ant_acrobatic", "humanoid_dribbling", "humanoid_tightrope", "trifinger_lift", "c4_walker"]


def entry_kinds(section):
    return {e["name"]: e["kind"] for e in (section or [])}


def check_layout(task, sym, names, matrices, spec_section, failures, what):
    central, limb = entry_kinds(spec_section.get("central")), entry_kinds(spec_section.get("limb"))
    mirror = sym.group_type == "reflection"
    n = sym.order
    for i in range(1, n):
        T = matrices[i]
        shifts = set()
        for r, name in enumerate(names):
            m = re.fullmatch(r"(central|limb(\d+))\.([A-Za-z0-9_]+)", name)
            if not m:
                continue  # a component of a multi-dimensional entry (name[k])
            entry = m.group(3)
            kind = (central if m.group(1) == "central" else limb).get(entry)
            if kind not in ("invariant", "odd"):
                continue
            cols = np.flatnonzero(np.abs(T[r]) > 1e-12)
            if len(cols) != 1:
                failures.append(f"{task}: {what} T_{i} row {name} has {len(cols)} nonzeros, a 1-D {kind} entry has 1")
                continue
            target = re.fullmatch(r"(central|limb(\d+))\.([A-Za-z0-9_]+)", names[cols[0]])
            if target is None or target.group(3) != entry or (target.group(1) == "central") != (m.group(1) == "central"):
                failures.append(f"{task}: {what} T_{i} maps {name} from {names[cols[0]]}, expected the same entry")
                continue
            sign = T[r, cols[0]]
            want = -1.0 if (kind == "odd" and mirror) else 1.0
            if kind == "invariant" or mirror:
                if sign != want:
                    failures.append(f"{task}: {what} T_{i} row {name} has sign {sign}, a {kind} entry {want}")
            if m.group(2) is not None:
                shifts.add((int(m.group(2)) - int(target.group(2))) % n)
        if limb and len(shifts) != 1:
            failures.append(f"{task}: {what} T_{i} moves the limbs by shifts {sorted(shifts)}, expected one shift")
        elif limb and shifts.pop() not in (i % n, (n - i) % n):
            failures.append(f"{task}: {what} T_{i} does not shift the limbs by {i}")


def check_task(task, failures):
    sym = masa.symmetry(task)
    spec = yaml.safe_load(open(sym.source))
    if sym.order != (2 if spec["group"]["type"] == "reflection" else spec["group"]["order"]):
        failures.append(f"{task}: group order {sym.order} differs from the spec's")
    for what, dim, matrix, names, transform, section in (
            ("observation", sym.obs_dim, sym.obs_matrix, sym.obs_names, sym.transform_obs, spec["observation"]),
            ("action", sym.act_dim, sym.act_matrix, sym.act_names, sym.transform_act, spec["action"])):
        T = [matrix(i) for i in range(sym.order)]
        if not np.array_equal(T[0], np.eye(dim)):
            failures.append(f"{task}: {what} T_0 is not the identity")
        for i in range(sym.order):
            if not np.allclose(T[i] @ T[i].T, np.eye(dim), atol=1e-9):
                failures.append(f"{task}: {what} T_{i} is not orthogonal")
            if not np.allclose(np.linalg.matrix_power(T[1], i), T[i], atol=1e-9):
                failures.append(f"{task}: {what} T_{i} is not T_1^{i}")
            x = np.random.default_rng(i).standard_normal((5, dim)).astype(np.float32)
            if not np.allclose(transform(x, i), x @ T[i].T.astype(np.float32), atol=1e-5):
                failures.append(f"{task}: transforming {what} rows by T_{i} differs from its matrix")
            if not np.allclose(transform(x[0], i), transform(x, i)[0]):
                failures.append(f"{task}: one {what} row transforms differently from a batch's")
        if not np.allclose(np.linalg.matrix_power(T[1], sym.order), np.eye(dim), atol=1e-9):
            failures.append(f"{task}: {what} T_1^N is not the identity")
        check_layout(task, sym, names, T, section, failures, what)


def layout_check_catches_a_wrong_sign():
    """The layout check itself can fail: a1_beam's T_1 with one invariant row's sign flipped."""
    sym = masa.symmetry("a1_beam")
    spec = yaml.safe_load(open(sym.source))
    T = [sym.obs_matrix(i) for i in range(sym.order)]
    T[1][sym.obs_names.index("limb0.front_thigh_pos")] *= -1
    caught = []
    check_layout("a1_beam", sym, sym.obs_names, T, spec["observation"], caught, "observation")
    return len(caught) == 1


def main():
    failures = []
    for task in SPEC_TASKS:
        check_task(task, failures)
    if not layout_check_catches_a_wrong_sign():
        failures.append("the layout check missed a flipped sign")
    # The equivariance check of a callable.
    env = masa.make_env("a1_beam", num_envs=16, seed=3)
    obs, _ = env.reset()
    for _ in range(5):
        obs, *_ = env.step(np.zeros(env.action_space.shape, np.float32))
    shipped = masa.Policy.load(os.path.join(SOURCE, "tasks", "a1_beam", "policy", "policy.bin"))
    errors = {
        "shipped MASA": masa.check_equivariance(shipped, env.symmetry, obs),
        "fresh MASA": masa.check_equivariance(masa.Policy.initial("a1_beam", "masa", seed=1), env.symmetry, obs),
        "fresh SA": masa.check_equivariance(masa.Policy.initial("a1_beam", "sa", seed=1), env.symmetry, obs),
    }
    print("worst equivariance errors:", {k: f"{v:.2e}" for k, v in errors.items()})
    for k in ("shipped MASA", "fresh MASA"):
        if not errors[k] <= 1e-4:
            failures.append(f"the {k} policy fails the equivariance check ({errors[k]:.3g})")
    if not errors["fresh SA"] > 1e-3:
        failures.append(f"the fresh SA policy passes the equivariance check ({errors['fresh SA']:.3g})")
    try:
        masa.check_equivariance(masa.Policy.initial("a1_beam", "sa", seed=1), env.symmetry, obs, raise_error=True)
        failures.append("check_equivariance(raise_error=True) did not raise for SA")
    except masa.EquivarianceError:
        pass
    if not failures:
        print(f"PASS: the transforms of {len(SPEC_TASKS)} tasks are their specs'; the check passes MASA and fails SA")
    return failures


run(main)
