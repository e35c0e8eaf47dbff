#!/usr/bin/python3
"""Checks a policy exported by masa_export without masa: onnx's checker (with shape inference),
then an evaluation of the graph by a walk over its nodes in numpy (float64), compared with masa's
own action means in the reference file that masa_export wrote.

    check_onnx_policy.py POLICY.onnx REFERENCE.txt [--tolerance 1e-5]

Prints "OK: ..." and exits 0, or "FAIL: ..." and exits 1; exits 77 (skip) without onnx or numpy.
Debian 12's python3-onnx (1.12) has no reference evaluator, hence the walk: it knows the handful of
operators masa emits and fails on any other.
"""
import argparse
import sys

try:
    import numpy as np
    import onnx
    from onnx import numpy_helper
except ImportError as e:  # python3-onnx or python3-numpy missing
    print(f"SKIP: {e}")
    sys.exit(77)


def attributes(node):
    return {a.name: onnx.helper.get_attribute_value(a) for a in node.attribute}


def gemm(a, b, c=None, alpha=1.0, beta=1.0, transA=0, transB=0):
    y = alpha * ((a.T if transA else a) @ (b.T if transB else b))
    return y if c is None else y + beta * c


def reshape(x, shape):
    # ONNX's 0 copies the input's dimension (allowzero = 0); -1 is inferred as in numpy.
    shape = [x.shape[i] if d == 0 else int(d) for i, d in enumerate(shape)]
    return x.reshape(shape)


def elu(x, alpha=1.0):
    return np.where(x > 0, x, alpha * np.expm1(np.minimum(x, 0)))


OPS = {
    "Sub": lambda a, b: a - b,
    "Mul": lambda a, b: a * b,
    "Add": lambda a, b: a + b,
    "MatMul": lambda a, b: a @ b,
    "Gemm": gemm,
    "Reshape": reshape,
    "Elu": elu,
    "Tanh": np.tanh,
    "Relu": lambda x: np.maximum(x, 0),
    "Identity": lambda x: x,
}


def evaluate(model, observation):
    """Runs the graph on one batch of observations; returns its outputs by name."""
    values = {t.name: numpy_helper.to_array(t).astype(np.float64) if t.data_type == onnx.TensorProto.FLOAT
              else numpy_helper.to_array(t) for t in model.graph.initializer}
    values[model.graph.input[0].name] = observation
    for node in model.graph.node:
        attrs = attributes(node)
        if node.op_type == "Constant":
            result = numpy_helper.to_array(attrs["value"]).astype(np.float64)
        elif node.op_type in OPS:
            result = OPS[node.op_type](*[values[i] for i in node.input], **attrs)
        else:
            raise ValueError(f"operator {node.op_type} (node {node.name}) is not one masa emits")
        values[node.output[0]] = result
    return {o.name: values[o.name] for o in model.graph.output}


def read_reference(path):
    with open(path) as f:
        f.readline()
        dims = f.readline().split()
        obs_dim, act_dim = int(dims[2]), int(dims[4])
        log_std = np.array([float(v) for v in f.readline().split()[2:]])
    rows = np.loadtxt(path, ndmin=2)
    assert rows.shape[1] == obs_dim + act_dim, f"reference has {rows.shape[1]} columns, not {obs_dim} + {act_dim}"
    return rows[:, :obs_dim], rows[:, obs_dim:], log_std


def declared_shape(value_info):
    return [d.dim_param or d.dim_value for d in value_info.type.tensor_type.shape.dim]


def check(onnx_path, reference_path, tolerance):
    model = onnx.load(onnx_path)
    onnx.checker.check_model(model, full_check=True)  # full_check: shape inference too
    obs, masa_mean, masa_log_std = read_reference(reference_path)
    obs_dim, act_dim = obs.shape[1], masa_mean.shape[1]
    shapes = {v.name: declared_shape(v) for v in list(model.graph.input) + list(model.graph.output)}
    expected = {"observation": ["batch", obs_dim], "action_mean": ["batch", act_dim], "log_std": [act_dim]}
    if shapes != expected:
        return f"inputs and outputs are {shapes}, expected {expected}"
    metadata = {p.key: p.value for p in model.metadata_props}
    for key in ("task", "method", "observation_names", "action_names", "masa_commit"):
        if not metadata.get(key):
            return f"metadata '{key}' is missing"
    if len(metadata["observation_names"].split(",")) != obs_dim:
        return f"metadata names {len(metadata['observation_names'].split(','))} observations, not {obs_dim}"

    # A squashed (SAC) policy's action is a Tanh's output, the last node on the way to action_mean.
    squash = metadata.get("action_squash", "none")
    if squash == "tanh":
        producers = [n for n in model.graph.node if "action_mean" in n.output]
        if len(producers) != 1 or producers[0].op_type != "Tanh":
            return "metadata action_squash is tanh, but action_mean is not the output of a Tanh node"
    elif squash != "none":
        return f"metadata action_squash '{squash}' is neither none nor tanh"

    out = evaluate(model, obs)
    mean_error = np.max(np.abs(out["action_mean"] - masa_mean))
    log_std_error = np.max(np.abs(out["log_std"] - masa_log_std))
    # The batch is free: one sample alone gives its row of the batch.
    single = evaluate(model, obs[-1:])["action_mean"]
    batch_error = np.max(np.abs(single - out["action_mean"][-1:]))
    summary = (f"{metadata['task']} {metadata['method']} (squash {squash}), {len(model.graph.node)} nodes, {len(obs)} samples: "
               f"action_mean max |onnx - masa| {mean_error:.2e}, log_std {log_std_error:.2e}, "
               f"batch of 1 {batch_error:.2e} (tolerance {tolerance:g}, |action_mean| up to {np.max(np.abs(masa_mean)):.2f})")
    if not (mean_error <= tolerance and log_std_error <= tolerance and batch_error <= tolerance):
        return summary
    print(f"OK: {onnx_path}: {summary}")
    return None


def main():
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("onnx")
    parser.add_argument("reference")
    parser.add_argument("--tolerance", type=float, default=1e-5)
    args = parser.parse_args()
    try:
        failure = check(args.onnx, args.reference, args.tolerance)
    except Exception as e:  # the checker's ValidationError, an unknown operator, a bad reference
        failure = f"{type(e).__name__}: {e}"
    if failure:
        print(f"FAIL: {args.onnx}: {failure}")
        return 1
    return 0


if __name__ == "__main__":
    sys.exit(main())
