#!/usr/bin/env python3
"""Trains a small policy with PyTorch on a masa task, with masa's symmetry transforms as data
augmentation: behaviour cloning of the shipped a1_beam policy (the teacher) by an MLP (the
student). Every observation the teacher saw is also given in its mirror image T_i o with the
mirrored action T_i a as target, so the student learns the symmetry from data (it is not built
in, as in MASA). At the end: the student's return against the teacher's on fresh episodes, and
its equivariance error next to a student trained without augmentation.
    PYTHONPATH=build/python /usr/bin/python3 python/examples/train_torch.py [--quick]
Run from the repository root; needs PyTorch (Debian: apt-get install python3-torch)."""
import sys

import numpy as np
import torch

import masa

QUICK = "--quick" in sys.argv
torch.manual_seed(0)
teacher = masa.Policy.load("tasks/a1_beam/policy/policy.bin")
env = teacher.make_env(num_envs=16)
sym = env.symmetry


def collect(steps, seed):
    """Observations along the teacher's own episodes, with its actions."""
    obs, _ = env.reset(seed=seed)
    o, a = [], []
    for _ in range(steps):
        act = teacher.act(obs)
        o.append(obs)
        a.append(act)
        obs, *_ = env.step(act)
    return np.concatenate(o), np.concatenate(a)


def augment(obs, act):
    """Every sample under every group element: (T_i o, T_i a) for i = 0..N-1."""
    return (np.concatenate([sym.transform_obs(obs, i) for i in range(sym.order)]),
            np.concatenate([sym.transform_act(act, i) for i in range(sym.order)]))


def train(obs, act, iterations):
    mean, std = obs.mean(0), obs.std(0) + 1e-3
    net = torch.nn.Sequential(torch.nn.Linear(obs.shape[1], 128), torch.nn.ELU(), torch.nn.Linear(128, 128),
                              torch.nn.ELU(), torch.nn.Linear(128, act.shape[1]))
    x, y = torch.as_tensor((obs - mean) / std), torch.as_tensor(act)
    opt = torch.optim.Adam(net.parameters(), lr=1e-3)
    gen = torch.Generator().manual_seed(0)
    for _ in range(iterations):
        idx = torch.randint(0, len(x), (256,), generator=gen)
        loss = torch.nn.functional.mse_loss(net(x[idx]), y[idx])
        opt.zero_grad()
        loss.backward()
        opt.step()

    def act_fn(o):
        with torch.no_grad():
            return net(torch.as_tensor((np.asarray(o, np.float32) - mean) / std)).numpy()
    return act_fn, float(loss)


def mean_return(act_fn, steps, seed):
    obs, _ = env.reset(seed=seed)
    total = np.zeros(env.num_envs)
    for _ in range(steps):
        obs, reward, *_ = env.step(np.clip(act_fn(obs), -1, 1).astype(np.float32))
        total += reward
    return total.mean()


steps, iterations = (100, 300) if QUICK else (400, 3000)
obs, act = collect(steps, seed=0)
student, loss = train(*augment(obs, act), iterations)
plain, plain_loss = train(obs.astype(np.float32), act, iterations)
print(f"trained on {len(obs)} teacher steps x {sym.order} symmetry images, final loss {loss:.4f}")
probe = collect(20, seed=100)[0]
returns = {}
for name, fn in (("teacher", teacher.act), ("student (augmented)", student), ("student (plain)", plain)):
    returns[name] = mean_return(fn, steps, seed=1000)
    print(f"{name:22s} return over {steps} steps: {returns[name]:9.2f}   "
          f"equivariance error: {masa.check_equivariance(fn, sym, probe):.2e}")
learned = returns["student (augmented)"] > 0.5 * returns["teacher"]
print("the student walks: its return is over half the teacher's" if learned else "the student did NOT learn: its return is under half the teacher's")
sys.exit(0 if learned else 1)
