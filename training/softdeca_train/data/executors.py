"""Where shards are simulated: in this process, in local worker processes (default: one per
core, each simulator single-threaded), or on a Ray cluster. Every executor yields
(spec, arrays, info) as shards finish, in any order; the driver alone writes files."""

from __future__ import annotations

import contextlib
import ctypes
import multiprocessing as mp
import os
import signal
from collections.abc import Callable, Iterable, Iterator
from concurrent.futures import FIRST_COMPLETED, Future, ProcessPoolExecutor, wait
from typing import Any

from softdeca_train.data.config import GenerateConfig
from softdeca_train.data.plan import ShardSpec
from softdeca_train.data.simulate import simulate_shard

Result = tuple[ShardSpec, dict, dict]
# Workers run numpy's BLAS on one thread: a multi-threaded GEMM may round differently, and a
# shard must be bit-identical whichever executor made it (Ray does the same by default).
SINGLE_THREADED = {"OMP_NUM_THREADS": "1", "OPENBLAS_NUM_THREADS": "1", "MKL_NUM_THREADS": "1"}


@contextlib.contextmanager
def _environment(values: dict[str, str]) -> Iterator[None]:
    """os.environ with `values` while the block runs (spawned children inherit it)."""
    saved = {k: os.environ.get(k) for k in values}
    os.environ.update(values)
    try:
        yield
    finally:
        for k, v in saved.items():
            if v is None:
                os.environ.pop(k, None)
            else:
                os.environ[k] = v


def _die_with_parent() -> None:
    """Worker initializer: a killed generator takes its workers along (Linux), so nothing
    keeps burning CPU for shards that no one will write."""
    with contextlib.suppress(OSError, AttributeError):
        ctypes.CDLL("libc.so.6", use_errno=True).prctl(1, signal.SIGKILL)  # PR_SET_PDEATHSIG


def _in_flight(
    specs: list[ShardSpec],
    limit: int,
    submit: Callable[[ShardSpec], Any],
    finished: Callable[[list[Any]], Iterable[Any]],
    result: Callable[[Any], tuple[dict, dict]],
) -> Iterator[Result]:
    """At most `limit` shards in flight (so a kill loses little), each yielded as it finishes:
    `submit` starts one, `finished` waits for some of the pending handles, `result` reads one."""
    todo = iter(specs)
    pending: dict[Any, ShardSpec] = {}

    def fill() -> None:
        while len(pending) < limit:
            spec = next(todo, None)
            if spec is None:
                return
            pending[submit(spec)] = spec

    fill()
    while pending:
        for handle in finished(list(pending)):
            spec = pending.pop(handle)
            arrays, info = result(handle)
            yield spec, arrays, info
        fill()


def run_inline(
    specs: list[ShardSpec], cfg: GenerateConfig, ict: str | None, threads: int
) -> Iterator[Result]:
    """In this process (debugging, tiny runs). numpy's BLAS keeps this process's threads, so
    the last bits may differ from shards made by worker processes or Ray."""
    for spec in specs:
        arrays, info = simulate_shard(spec, cfg, ict, threads)
        yield spec, arrays, info


def run_processes(
    specs: list[ShardSpec], cfg: GenerateConfig, ict: str | None, threads: int, workers: int
) -> Iterator[Result]:
    """A pool of `workers` processes (spawned: no inherited native state), at most two shards
    queued per worker so a kill loses little."""
    ctx = mp.get_context("spawn")
    with (
        _environment(SINGLE_THREADED),
        ProcessPoolExecutor(workers, mp_context=ctx, initializer=_die_with_parent) as pool,
    ):
        yield from _in_flight(
            specs,
            2 * workers,
            lambda spec: pool.submit(simulate_shard, spec, cfg, ict, threads),
            lambda pending: wait(pending, return_when=FIRST_COMPLETED)[0],
            Future.result,
        )


def run_ray(
    specs: list[ShardSpec],
    cfg: GenerateConfig,
    ict: str | None,
    threads: int,
    address: str,
    workers: int,
) -> Iterator[Result]:
    """The same tasks on Ray. `address` "local" starts a private local instance with
    `workers` CPUs; otherwise connect (e.g. "ray://head:10001" or "auto"). Cluster nodes need
    this package, softdeca_native and ICT-FaceKit (the --ict path) installed alike."""
    try:
        import ray  # optional: only the Ray executor needs it
    except ImportError as e:
        raise ValueError("--ray-address needs the ray package (pip install ray)") from e
    keep = ("PYTHONPATH", "SOFTDECA_ICT", "SOFTDECA_DATA", "SOFTDECA_CACHE")
    env = {k: os.environ[k] for k in keep if k in os.environ} | SINGLE_THREADED
    if "PYTHONPATH" in env:  # Ray's workers start elsewhere: relative entries would break
        env["PYTHONPATH"] = os.pathsep.join(
            os.path.abspath(p) for p in env["PYTHONPATH"].split(os.pathsep) if p
        )
    kw: dict[str, Any] = {"include_dashboard": False, "log_to_driver": False}
    if address == "local":
        ray.init(num_cpus=max(1, workers), runtime_env={"env_vars": env}, **kw)
    else:
        ray.init(address=address, **kw)
    try:
        task = ray.remote(num_cpus=threads)(simulate_shard)
        capacity = max(1, int(ray.cluster_resources().get("CPU", 1)) // threads)
        yield from _in_flight(
            specs,
            2 * capacity,
            lambda spec: task.remote(spec, cfg, ict, threads),
            lambda pending: ray.wait(pending, num_returns=1)[0],
            ray.get,
        )
    finally:
        ray.shutdown()
