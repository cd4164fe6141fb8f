"""Files: tables (CSV, Parquet, npy/npz, MATLAB .mat) in and out, model files.

One module per job; ``docs/architecture.md`` lists them.
"""

from clpc.io.errors import DataFileNotFoundError
from clpc.io.loading import iter_table_chunks, read_table, table_columns
from clpc.io.model_files import ModelFileError, load_model, save_model
from clpc.io.records import load_iodata
from clpc.io.table import Table
from clpc.io.writing import write_table

__all__ = [
    "DataFileNotFoundError",
    "ModelFileError",
    "Table",
    "iter_table_chunks",
    "load_iodata",
    "load_model",
    "read_table",
    "save_model",
    "table_columns",
    "write_table",
]
