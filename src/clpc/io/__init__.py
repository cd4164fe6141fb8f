"""Files: tables (CSV, Parquet, npy/npz) in and out, model files."""

from clpc.io.model_files import ModelFileError, load_model, save_model
from clpc.io.tables import (
    DataFileNotFoundError,
    Table,
    iter_table_chunks,
    load_iodata,
    read_table,
    write_table,
)

__all__ = [
    "DataFileNotFoundError",
    "ModelFileError",
    "Table",
    "iter_table_chunks",
    "load_iodata",
    "load_model",
    "read_table",
    "save_model",
    "write_table",
]
