#!/usr/bin/env python3
"""The cost model of docs/scaling.md: training fps of an actor-learner job from measured per-sample
costs, the next bottleneck, and the network load, for K nodes x C cores; and its check against
measured points.

One update takes a batch of B = A x E x H samples (A actors of E environments, horizon H):
  rollout   T_roll = E * H * t_env                     every actor on a core of its own
  update    T_upd  = (B / L) * t_learn / s(T) + coll(L) L ranks of T threads; s: thread speed-up
  broadcast T_bc   = param_bytes / NIC (+ latency)      0 on one node
Each phase runs on the cores it finds (A actors on min(A, C) cores: T_roll x max(1, A / C); the
L x T learner threads likewise), and the lag says whether the phases take turns or overlap:
  ppo.max_policy_lag 0:  T = T_roll + T_upd + T_bc        (actors and learner take turns)
  ppo.max_policy_lag 1:  T = max(T_roll, T_upd + T_bc, B (t_env + t_learn) / min(C, A + L T))
                         (the actor collects the next rollout while the learner learns:
                         actors/policy_lag_window.hpp; the cores cannot do more than their work)
fps = B / T. The bound of issue #30 is cores / (t_env + t_learn), cores = the cores the job uses.
Network, per second: every host that joins the rollout group receives fps x bytes_per_sample (LCM
multicast: a NIC takes every datagram of the group; the kernel filters ports), every actor host the
parameters (param_bytes per update), and each rank 2 (L-1)/L x gradient bytes per minibatch.

  bench/scaling_model.py costs.json predict A E H L T [--cores C] [--nodes K] [--lag 0|1]
  bench/scaling_model.py costs.json plan E H --cores C [--nodes K] [--lag 0|1] [--terse]   (the fastest split into actors and ranks)
  bench/scaling_model.py costs.json check points.txt   (lines: "fps|update_ms  MEASURED  A E H L T CORES LAG")
costs.json: t_env_us, t_learn_us (per sample, one thread), thread_speedup {"2": 1.29, ...},
allreduce_us {"2": 4288, ...} (the gradient allreduce of one minibatch at L ranks on one node),
minibatches_x_epochs (allreduces per update), param_bytes, bytes_per_sample, grad_bytes, nic_gbps,
nic_latency_us (bench/scaling_check.sh measures and writes it).
"""
import json
import sys


def thread_speedup(c, t):
    return 1.0 if t == 1 else float(c["thread_speedup"].get(str(t), t * 0.65))


def collectives_ms(c, ranks, nodes):
    """All collectives of one update: the gradient allreduce of every minibatch dominates (the
    statistics' allreduces are a few doubles each)."""
    if ranks == 1:
        return 0.0
    per_mb = c["allreduce_us"].get(str(ranks))
    if per_mb is None:  # a ring allreduce moves 2 (L-1)/L of the buffer: scale the largest measured
        known = max(int(k) for k in c["allreduce_us"])
        per_mb = c["allreduce_us"][str(known)] * (2 * (ranks - 1) / ranks) / (2 * (known - 1) / known)
    measured = per_mb * c["minibatches_x_epochs"] / 1e3
    if nodes > 1:  # the gradient crosses the NIC once per minibatch (ring: 2 (L-1)/L of it)
        per_mb_s = 2 * (ranks - 1) / ranks * c["grad_bytes"] / (c["nic_gbps"] * 1e9 / 8) + 2 * c["nic_latency_us"] * 1e-6
        measured += 1e3 * per_mb_s * c["minibatches_x_epochs"]
    return measured


def predict(c, actors, envs, horizon, ranks, threads, cores=None, nodes=1, lag=0):
    batch = actors * envs * horizon
    t_env, t_learn = c["t_env_us"] * 1e-6, c["t_learn_us"] * 1e-6
    procs = actors + ranks * threads
    cores = cores if cores else procs
    coll = collectives_ms(c, ranks, nodes) * 1e-3
    bcast = 0.0 if nodes == 1 else c["param_bytes"] / (c["nic_gbps"] * 1e9 / 8) + c["nic_latency_us"] * 1e-6
    # Each phase runs on the cores it finds: A actors on min(A, C) cores, L x T learner threads on
    # min(L T, C) (more processes than cores: they share them).
    parts = {
        "rollout": envs * horizon * t_env * max(1.0, actors / cores),
        "update": batch / ranks * t_learn / thread_speedup(c, threads) * max(1.0, ranks * threads / cores),
        "collectives": coll,
        "broadcast": bcast,
    }
    if lag >= 1:  # overlapped, but the cores cannot do more work than they have
        cycle = max(parts["rollout"], parts["update"] + coll + bcast, batch * (t_env + t_learn) / min(cores, procs))
    else:
        cycle = parts["rollout"] + parts["update"] + coll + bcast
    fps = batch / cycle
    bound = min(cores, procs) / (t_env + t_learn)
    nic_in = fps * c["bytes_per_sample"] if nodes > 1 else 0.0
    nic_cap = c["nic_gbps"] * 1e9 / 8
    if nic_in > nic_cap:
        fps, parts["nic"] = fps * nic_cap / nic_in, nic_in / nic_cap
    next_bottleneck = max(parts, key=parts.get)
    if nodes > 1 and nic_in > 0.5 * nic_cap:
        next_bottleneck = "a learner host's NIC under multicast (%.0f%% of it)" % (100 * nic_in / nic_cap)
    return {"fps": fps, "bound": bound, "efficiency": fps / bound, "update_ms": 1e3 * (parts["update"] + coll),
            "parts_ms": {k: 1e3 * v for k, v in parts.items()}, "next": next_bottleneck,
            "rollout_MBps_per_host": nic_in / 1e6, "cores": min(cores, procs)}


def plan(c, envs, horizon, cores, nodes=1, lag=0):
    """The fastest split of cores x nodes into A actors and L single-thread ranks (A a multiple of
    L), on cores of their own or sharing them: (A, L, prediction). Ties go to fewer processes."""
    total = cores * nodes
    best = None
    for ranks in range(1, total + 1):
        for actors in range(ranks, total + 1, ranks):
            p = predict(c, actors, envs, horizon, ranks, 1, cores=total, nodes=nodes, lag=lag)
            if best is None or p["fps"] > best[2]["fps"] * (1 + 1e-9):
                best = (actors, ranks, p)
    return best


def main(argv):
    if len(argv) < 3:
        print(__doc__)
        return 2
    with open(argv[1]) as f:
        c = json.load(f)
    if argv[2] == "predict":
        a, e, h, l, t = (int(x) for x in argv[3:8])
        opts = argv[8:]
        kw = {"cores": None, "nodes": 1, "lag": 0}
        for i, o in enumerate(opts):
            if o in ("--cores", "--nodes", "--lag"):
                kw[o[2:]] = int(opts[i + 1])
        p = predict(c, a, e, h, l, t, **kw)
        print("fps %.0f  bound %.0f  efficiency %.2f  update %.1f ms  next bottleneck: %s  rollout traffic %.1f MB/s a host"
              % (p["fps"], p["bound"], p["efficiency"], p["update_ms"], p["next"], p["rollout_MBps_per_host"]))
        print("  per update (ms): " + ", ".join("%s %.1f" % kv for kv in p["parts_ms"].items()))
        return 0
    if argv[2] == "plan":  # the split of C cores (x K nodes) into actors and ranks the model finds fastest
        envs, horizon = int(argv[3]), int(argv[4])
        opts = argv[5:]
        kw = {"cores": 2, "nodes": 1, "lag": 0}
        for i, o in enumerate(opts):
            if o in ("--cores", "--nodes", "--lag"):
                kw[o[2:]] = int(opts[i + 1])
        a, l, p = plan(c, envs, horizon, **kw)
        if "--terse" in opts:  # for scripts: "ACTORS RANKS"
            print(a, l)
            return 0
        total = kw["cores"] * kw["nodes"]
        print("%d cores x %d nodes, lag %d: %d actors of %d environments and %d learner ranks (%s): fps %.0f (%.2f of the bound %.0f); next bottleneck: %s"
              % (kw["cores"], kw["nodes"], kw["lag"], a, envs, l, "cores of their own" if a + l <= total else "sharing the cores",
                 p["fps"], p["efficiency"], p["bound"], p["next"]))
        return 0
    if argv[2] == "check":
        worst = 0.0
        print("%-10s %10s %10s %6s  %s" % ("what", "measured", "model", "ratio", "point"))
        with open(argv[3]) as f:
            for line in f:
                line = line.split("#")[0].split()
                if not line:
                    continue
                what, measured = line[0], float(line[1])
                a, e, h, l, t, cores, lag = (int(x) for x in line[2:9])
                p = predict(c, a, e, h, l, t, cores=cores, lag=lag)
                model = p["fps"] if what == "fps" else p["update_ms"]
                ratio = measured / model
                worst = max(worst, abs(ratio - 1))
                print("%-10s %10.0f %10.0f %6.2f  A=%d E=%d H=%d L=%d T=%d cores=%d lag=%d  (bound %.0f, model's next: %s)"
                      % (what, measured, model, ratio, a, e, h, l, t, cores, lag, p["bound"], p["next"]))
        print("largest departure from the model: %.0f%%" % (100 * worst))
        return 0
    print(__doc__)
    return 2


if __name__ == "__main__":
    sys.exit(main(sys.argv))
