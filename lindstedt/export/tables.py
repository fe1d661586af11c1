"""Results as pandas DataFrames (pandas is optional: ``pip install 'lindstedt[pandas]'``).

Every tabular result (NNM sweeps and branches, backbones, frequency responses) builds its table here, so
that the missing-dependency error is one and the same.

Examples
--------
>>> from lindstedt.export.tables import dataframe
>>> dataframe([{"a": 1, "b": 2.5}, {"a": 2, "b": 3.5}]).values.tolist()
[[1.0, 2.5], [2.0, 3.5]]
"""

from __future__ import annotations

from typing import Any, Mapping, Sequence

__all__ = ["dataframe", "require_pandas"]


def require_pandas() -> Any:
    """The pandas module, or a :class:`~lindstedt.LindstedtError` naming how to install it."""
    try:
        import pandas
    except ImportError as error:
        from .._errors import LindstedtError

        raise LindstedtError("tables need pandas: pip install pandas (or pip install 'lindstedt[pandas]')") from error
    return pandas


def dataframe(rows: Sequence[Mapping[str, Any]], columns: Sequence[str] | None = None) -> Any:
    """A DataFrame with one row per mapping (columns in the order of the first row, or ``columns``)."""
    pandas = require_pandas()
    return pandas.DataFrame(list(rows), columns=list(columns) if columns is not None else None)
