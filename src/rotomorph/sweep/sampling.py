"""Points of a sweep: the full grid, independent random draws, or a Latin hypercube.

``grid`` takes the Cartesian product of every parameter's values (lists and ranges; the last
parameter varies fastest). ``random`` and ``latin_hypercube`` draw ``samples`` points with the
sweep's ``seed`` (NumPy's PCG64 generator): a uniform
``u`` in [0, 1) per parameter is mapped through the parameter's inverse distribution —
``low + u (high - low)`` (uniform), ``exp`` of that in logs (loguniform), the normal quantile
(truncated to [low, high] when given) — or picks ``values[floor(u n)]`` of a list or range, so a
Latin hypercube also stratifies discrete parameters. The Latin hypercube (McKay, Beckman and
Conover, Technometrics 21, 1979) puts, for every parameter, exactly one of the ``n`` points in
each of ``n`` equal slices of [0, 1): ``u = (permutation(n) + U[0, 1)) / n`` per column. The
same sweep file always gives the same points, in the same order.
"""

from __future__ import annotations

import itertools
import math
from typing import Any

import numpy as np

from rotomorph.sweep.spec import Parameter, Sweep

__all__ = ["sample_points"]


def _from_unit(param: Parameter, u: np.ndarray) -> list[Any]:
    levels = param.levels()
    if levels is not None:
        idx = np.minimum((u * len(levels)).astype(int), len(levels) - 1)
        return [levels[i] for i in idx]
    dist = param.distribution
    assert dist is not None
    if dist.kind == "uniform":
        assert dist.low is not None and dist.high is not None
        x = dist.low + u * (dist.high - dist.low)
    elif dist.kind == "loguniform":
        assert dist.low is not None and dist.high is not None
        a, b = math.log(dist.low), math.log(dist.high)
        x = np.exp(a + u * (b - a))
    else:
        from scipy.special import ndtr, ndtri

        assert dist.mean is not None and dist.std is not None
        lo = 0.0 if dist.low is None else ndtr((dist.low - dist.mean) / dist.std)
        hi = 1.0 if dist.high is None else ndtr((dist.high - dist.mean) / dist.std)
        x = dist.mean + dist.std * ndtri(lo + u * (hi - lo))
    return [float(v) for v in x]


def sample_points(sweep: Sweep) -> list[dict[str, Any]]:
    """The sweep's points in order: one mapping ``{parameter path: value}`` per point."""
    params = sweep.parameters
    method = sweep.sampling.method
    if method == "grid":
        levels = [p.levels() or [] for p in params]
        return [
            {p.path: v for p, v in zip(params, combo, strict=True)}
            for combo in itertools.product(*levels)
        ]
    n = int(sweep.sampling.samples or 0)
    rng = np.random.default_rng(sweep.sampling.seed)
    if method == "random":
        u = rng.random((n, len(params)))
    else:
        u = np.stack([(rng.permutation(n) + rng.random(n)) / n for _ in params], axis=1)
    columns = [_from_unit(p, u[:, j]) for j, p in enumerate(params)]
    return [{p.path: columns[j][i] for j, p in enumerate(params)} for i in range(n)]
