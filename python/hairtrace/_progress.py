"""``render(progress=True)``: a tqdm bar over the render's pixels, where tqdm is installed."""

from __future__ import annotations

import warnings
from typing import Callable, Optional


def bar() -> Optional[Callable[[int, int], None]]:
    """A progress callback drawing a tqdm bar, or None (with a warning) without tqdm."""
    try:
        from tqdm.auto import tqdm
    except ImportError:
        warnings.warn("progress=True shows a bar with tqdm: pip install tqdm", stacklevel=3)
        return None
    state: dict[str, Optional[tqdm]] = {"bar": None}

    def update(done: int, total: int) -> None:
        if state["bar"] is None:
            state["bar"] = tqdm(total=total, unit="px", unit_scale=True, desc="render")
        b = state["bar"]
        b.update(done - b.n)
        if done >= total:
            b.close()

    return update
