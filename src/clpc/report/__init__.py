"""Reports: HTML and Markdown summaries of fits and traces."""

from clpc.report.html import (
    Section,
    format_fit,
    format_model_summary,
    jsonable,
    model_response,
    model_summary,
    steady_state,
    trace_columns,
    trace_summary,
    update_records,
    verdict_text,
    write_html_report,
    write_track_report,
)

__all__ = [
    "Section",
    "format_fit",
    "format_model_summary",
    "jsonable",
    "model_response",
    "model_summary",
    "steady_state",
    "trace_columns",
    "trace_summary",
    "update_records",
    "verdict_text",
    "write_html_report",
    "write_track_report",
]
