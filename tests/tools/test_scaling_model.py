#!/usr/bin/env python3
"""bench/scaling_model.py against cycles computed by hand (ScalingModel.* in ctest): the two lags,
processes sharing cores, the collectives of ranks, and the plan's split. Prints PASS or fails."""
import importlib.util
import sys

spec = importlib.util.spec_from_file_location("scaling_model", sys.argv[1])
m = importlib.util.module_from_spec(spec)
spec.loader.exec_module(m)
costs = {"t_env_us": 100.0, "t_learn_us": 50.0, "thread_speedup": {}, "allreduce_us": {"2": 1000.0},
         "minibatches_x_epochs": 20, "param_bytes": 1e6, "bytes_per_sample": 300.0, "grad_bytes": 4e5,
         "nic_gbps": 10, "nic_latency_us": 0}
failures = []


def near(what, got, want, tol=1e-6):
    if abs(got - want) > tol * max(1.0, abs(want)):
        failures.append("%s: %g, by hand %g" % (what, got, want))


# 1 actor of 10 envs x 10 steps, 1 rank, own cores: 100 samples; rollout 10 ms, update 5 ms.
near("lag 0 takes turns", m.predict(costs, 1, 10, 10, 1, 1, cores=2, lag=0)["fps"], 100 / 0.015)
near("lag 1 overlaps", m.predict(costs, 1, 10, 10, 1, 1, cores=2, lag=1)["fps"], 100 / 0.010)
near("the bound", m.predict(costs, 1, 10, 10, 1, 1, cores=2)["bound"], 2 / 150e-6)
# 4 actors on 2 cores: the rollout phase takes twice as long; 2 ranks: half the update each, plus
# 20 allreduces of 1 ms.
p = m.predict(costs, 4, 10, 10, 2, 1, cores=2, lag=0)
near("actors sharing cores", p["parts_ms"]["rollout"], 20.0)
near("ranks halve the update", p["parts_ms"]["update"], 10.0)
near("collectives", p["parts_ms"]["collectives"], 20.0)
near("lag 0 cycle", p["fps"], 400 / 0.050)
# Lag 1 on shared cores cannot beat the cores' total work: 400 x 150 us / 2 cores = 30 ms.
near("work bound", m.predict(costs, 4, 10, 10, 2, 1, cores=2, lag=1)["fps"], 400 / 0.030)
# 4 ranks: a ring moves 2 (L-1)/L of the buffer, 1.5 / 1 of the 2-rank allreduce.
near("ring scaling", m.predict(costs, 4, 10, 10, 4, 1, cores=8)["parts_ms"]["collectives"], 30.0)
# The plan on 3 cores with lag 1 (ranks' allreduce dear): 2 actors and 1 rank balance the rollout
# (10 ms) and the update (2 x 5 ms); 3 actors gain nothing more, so fewer processes win.
a, l, _ = m.plan(dict(costs, allreduce_us={"2": 1e6}), 10, 10, cores=3, lag=1)
if (a, l) != (2, 1):
    failures.append("plan on 3 cores: %d actors and %d ranks, by hand 2 and 1" % (a, l))
if failures:
    print("\n".join(failures))
    sys.exit(1)
print("PASS")
