"""Files: tables (CSV, Parquet, npy/npz, MATLAB .mat) in and out, model files.

Where each job lives (one module each):

- ``table``: the :class:`Table` container, column selection, the shared types;
- ``errors``: :class:`DataFileNotFoundError` and the one-line bad-cell messages;
- ``formats``: which format a file is (by its extension), and that it exists;
- ``text_format``: delimiter and header detection of text files;
- ``text_reader``: text files read by ``pyarrow.csv`` block by block, the first bad cell
  named by line, column and text; ``text_lines``: the data lines pyarrow is given (blank
  and comment lines out, each row's file line kept); ``text_writer``: writing text files;
- ``parquet``: Parquet in and out; ``numpy_files``: ``.npy``/``.npz`` in and out;
  ``npz_members``: ``.npz`` arrays read a block of rows at a time; ``mat_files``: MATLAB
  ``.mat`` in and out (``scipy.io``);
- ``loading``: :func:`read_table`, :func:`iter_table_chunks` (dispatch by extension);
- ``records``: :func:`load_iodata`; ``writing``: :func:`write_table`;
- ``model_schema``: the model file schema and :func:`~clpc.io.model_files.model_to_dict`;
- ``model_validation``: checking a decoded model file (``model_from_dict``);
- ``model_files``: :func:`save_model`, :func:`load_model`.
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
