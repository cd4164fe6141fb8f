"""Reports: HTML and Markdown summaries of fits and traces.

``jsonable`` (:func:`clpc.core.jsonable.jsonable`) and ``trace_columns``
(:func:`clpc.appraiser.tracefile.trace_columns`) are re-exported for the callers that took
them from here.
"""

from clpc.appraiser.tracefile import trace_columns
from clpc.core.jsonable import jsonable
from clpc.report.comparison import Comparison, compare
from clpc.report.html import Section, table_html, warnings_html, write_html_report
from clpc.report.identify import write_identify_report
from clpc.report.summaries import model_response, model_summary, verdict_text
from clpc.report.text import format_fit, format_model_summary
from clpc.report.trace_summary import steady_state, trace_summary, update_records
from clpc.report.track import write_track_report

__all__ = [
    "Comparison",
    "Section",
    "compare",
    "format_fit",
    "format_model_summary",
    "jsonable",
    "model_response",
    "model_summary",
    "steady_state",
    "table_html",
    "trace_columns",
    "trace_summary",
    "update_records",
    "verdict_text",
    "warnings_html",
    "write_html_report",
    "write_identify_report",
    "write_track_report",
]
