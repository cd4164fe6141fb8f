"""Where a long record's samples are read: slices of a file, read by the worker that needs them.

A source is small and picklable (a path and the column positions); :meth:`read` runs on the
worker and returns raw samples ``[inputs | outputs]`` of rows ``lo .. hi - 1``:

* :class:`NpySource`: a 2-D ``.npy`` file, memory-mapped (``numpy.load(mmap_mode="r")``), so
  a worker touches only the pages of its slice;
* :class:`ParquetSource`: a Parquet file, reading only the row groups that overlap the slice
  (``pyarrow.parquet.ParquetFile.read_row_groups``).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any

import numpy as np

from clpc.data import DataError
from clpc.io.table import resolve_columns

__all__ = ["NpySource", "ParquetSource", "open_source"]


@dataclass(frozen=True)
class NpySource:
    """Columns of a 2-D ``.npy`` file (names ``col0``, ``col1``, ... or 0-based positions).

    Parameters
    ----------
    path : str
        The file (every worker must see it at this path).
    inputs, outputs : tuple of str or int
        Input and output columns.
    """

    path: str
    inputs: tuple[str | int, ...]
    outputs: tuple[str | int, ...]

    def _array(self) -> np.ndarray:
        try:
            arr = np.load(self.path, mmap_mode="r", allow_pickle=False)
        except (ValueError, OSError, EOFError) as exc:
            raise DataError(f"{self.path} is not a readable .npy array ({exc}).") from None
        if arr.ndim != 2 or arr.dtype.names:
            raise DataError(
                f"{self.path}: a long record is a plain 2-D array (samples, channels); got "
                f"shape {arr.shape}, dtype {arr.dtype}. Save it with numpy.save(path, table)."
            )
        return arr

    def columns(self) -> list[int]:
        """Positions of the inputs, then the outputs."""
        names = [f"col{i}" for i in range(self._array().shape[1])]
        return resolve_columns(names, [*self.inputs, *self.outputs], self.path)

    def names(self) -> tuple[tuple[str, ...], tuple[str, ...]]:
        """Input and output names (``col<i>``)."""
        cols = [f"col{i}" for i in self.columns()]
        return tuple(cols[: len(self.inputs)]), tuple(cols[len(self.inputs) :])

    def length(self) -> int:
        """Rows (samples) of the record."""
        return int(self._array().shape[0])

    def read(self, lo: int, hi: int) -> np.ndarray:
        """Samples ``lo .. hi - 1`` of the selected columns, float64, shape (hi - lo, cols)."""
        return np.asarray(self._array()[lo:hi, self.columns()], dtype=np.float64)


@dataclass(frozen=True)
class ParquetSource:
    """Columns of a Parquet file, read row group by row group.

    Parameters
    ----------
    path : str
        The file (every worker must see it at this path).
    inputs, outputs : tuple of str or int
        Input and output columns (names, or 0-based positions).
    """

    path: str
    inputs: tuple[str | int, ...]
    outputs: tuple[str | int, ...]

    def _file(self) -> Any:
        import pyarrow as pa
        import pyarrow.parquet as pq

        try:
            return pq.ParquetFile(self.path)
        except (pa.ArrowInvalid, OSError) as exc:
            first = str(exc).splitlines()[0]
            raise DataError(f"{self.path} is not a readable Parquet file ({first}).") from None

    def _selected(self, pf: Any) -> list[str]:
        names = [str(n) for n in pf.schema_arrow.names]
        return [names[i] for i in resolve_columns(names, [*self.inputs, *self.outputs], self.path)]

    def names(self) -> tuple[tuple[str, ...], tuple[str, ...]]:
        """Input and output column names."""
        cols = tuple(self._selected(self._file()))
        return cols[: len(self.inputs)], cols[len(self.inputs) :]

    def length(self) -> int:
        """Rows (samples) of the record."""
        return int(self._file().metadata.num_rows)

    def read(self, lo: int, hi: int) -> np.ndarray:
        """Samples ``lo .. hi - 1`` of the selected columns, float64, shape (hi - lo, cols)."""
        pf = self._file()
        sizes = [pf.metadata.row_group(g).num_rows for g in range(pf.metadata.num_row_groups)]
        starts = np.concatenate([[0], np.cumsum(sizes)])
        groups = [g for g in range(len(sizes)) if starts[g] < hi and starts[g + 1] > lo]
        names = self._selected(pf)
        table = pf.read_row_groups(groups, columns=sorted(set(names)))
        first = int(starts[groups[0]]) if groups else lo
        cols = []
        for name in names:
            col = table.column(name).to_numpy(zero_copy_only=False)
            if col.dtype.kind not in "iufb":
                raise DataError(
                    f"{self.path}: column {name!r} holds {col.dtype} values; a long record's "
                    "columns must be numeric."
                )
            cols.append(np.asarray(col[lo - first : hi - first], dtype=np.float64))
        return np.column_stack(cols) if cols else np.empty((hi - lo, 0))


def open_source(
    path: str | Path, inputs: tuple[str | int, ...], outputs: tuple[str | int, ...]
) -> NpySource | ParquetSource:
    """The source of a ``.npy`` or Parquet (``.parquet``, ``.pq``) file.

    Raises
    ------
    DataError
        Another kind of file (those are read in chunks by ``clpc track`` on one machine).
    """
    name = str(path)
    if name.lower().endswith(".npy"):
        return NpySource(name, tuple(inputs), tuple(outputs))
    if name.lower().endswith((".parquet", ".pq")):
        return ParquetSource(name, tuple(inputs), tuple(outputs))
    raise DataError(
        f"{name}: a record split over workers must be a .npy or Parquet file (a worker reads "
        "its slice without reading the rest); convert it first (clpc.io.write_table), or "
        "track it on one machine."
    )
