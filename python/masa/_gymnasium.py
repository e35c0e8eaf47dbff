"""Registration with Gymnasium, when it is installed: every catalog task as masa/<task>-v0, made
with gymnasium.make_vec("masa/a1_beam-v0", num_envs=64). Without Gymnasium, nothing happens:
masa.make_env works the same."""


def _make_vec(task):
    def make(num_envs=1, **kwargs):
        from .env import make_env
        kwargs.pop("vectorization_mode", None)
        kwargs.pop("vector_kwargs", None)
        return make_env(task, num_envs=num_envs, **kwargs)
    return make


def register_with_gymnasium():
    """Registers the catalog's tasks; returns the ids registered (none without Gymnasium)."""
    try:
        import gymnasium
    except ImportError:
        return []
    from .env import task_names
    ids = []
    for task in task_names():
        env_id = f"masa/{task}-v0"
        if env_id in gymnasium.registry:
            continue
        try:
            gymnasium.register(id=env_id, vector_entry_point=_make_vec(task))
        except TypeError:  # a Gymnasium without vector entry points (before 1.0)
            return ids
        ids.append(env_id)
    return ids
