"""Read-only copies: result objects are immutable, and these make them so."""

from __future__ import annotations

from collections.abc import Mapping
from types import MappingProxyType
from typing import TYPE_CHECKING, Any

import numpy as np

if TYPE_CHECKING:  # pandas loads with the first Series or frame
    import pandas as pd


def frozen_array(values: Any, dtype: type = np.float64) -> np.ndarray:
    """A read-only 1-D copy of ``values`` (results are immutable)."""
    array = np.array(values, dtype=dtype, copy=True).reshape(-1)
    array.flags.writeable = False
    return array


def frozen_series(series: pd.Series) -> pd.Series:
    import pandas as pd

    """A copy of a float Series whose values cannot be assigned to."""
    return pd.Series(frozen_array(series.to_numpy()), index=series.index.copy(), name=series.name, copy=False)


def frozen_frame(frame: pd.DataFrame) -> pd.DataFrame:
    import pandas as pd

    """A copy of a float DataFrame whose values cannot be assigned to."""
    values = np.array(frame.to_numpy(dtype=np.float64), copy=True)
    values.flags.writeable = False
    return pd.DataFrame(values, index=frame.index.copy(), columns=frame.columns.copy(), copy=False)


def frozen_mapping(values: Mapping[str, Any]) -> Mapping[str, Any]:
    """A read-only view of a copy of ``values``."""
    return MappingProxyType(dict(values))
