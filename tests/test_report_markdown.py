"""The Markdown subset of the experiment's report as HTML (clpc_paper.experiment.markdown_html)."""

from __future__ import annotations

from clpc_paper.experiment.markdown_html import inline, markdown_to_html, split_sections


def test_inline_spans_and_escaping() -> None:
    assert inline("a **b** and *c* with `x <y> *z*`") == (
        "a <strong>b</strong> and <em>c</em> with <code>x &lt;y&gt; *z*</code>"
    )
    assert inline("<script> & 2 * 3 * 4") == "&lt;script&gt; &amp; 2 * 3 * 4"  # no raw HTML
    assert inline("- **ramp** - *not reproduced*: x") == (
        "- <strong>ramp</strong> - <em>not reproduced</em>: x"
    )


def test_pipe_table_with_escaped_bars_and_a_numeric_column() -> None:
    text = "| claim | figs | n |\n|---|---|---|\n| \\|p\\| < 1 | 6 | 1.5e-06 |\n| b | 7, 8 | - |"
    got = markdown_to_html(text, cell_class=lambda c: "bad" if c == "b" else None)
    assert got == (
        "<table><thead><tr><th>claim</th><th>figs</th><th>n</th></tr></thead><tbody>"
        '<tr><td>|p| &lt; 1</td><td>6</td><td class="num">1.5e-06</td></tr>'
        '<tr><td class="bad">b</td><td>7, 8</td><td class="num">-</td></tr>'
        "</tbody></table>"
    )


def test_image_with_its_caption_paragraph_becomes_one_figure() -> None:
    text = "![Fig. 5 command [rad]](fig05.png)\n\n*Fig. 5 command [rad]* (`fig05.png`)\n\nNext."
    assert markdown_to_html(text) == (
        '<figure><img alt="Fig. 5 command [rad]" src="fig05.png">'
        "<figcaption><em>Fig. 5 command [rad]</em> (<code>fig05.png</code>)</figcaption>"
        "</figure>\n<p>Next.</p>"
    )
    # without a caption paragraph the image stands alone; the paragraph stays a paragraph
    assert markdown_to_html("![a](a.png)\n\nOther.") == (
        '<figure><img alt="a" src="a.png"></figure>\n<p>Other.</p>'
    )


def test_lists_quotes_and_paragraphs() -> None:
    text = (
        "> **Paper:** words.\n\n**Criterion:** x.\n\n- one\n  continued\n- two\n\n"
        "A paragraph\nover two lines:\n| t |\n|---|\n| 1 |"
    )
    assert markdown_to_html(text) == (
        "<blockquote><p><strong>Paper:</strong> words.</p></blockquote>\n"
        "<p><strong>Criterion:</strong> x.</p>\n"
        "<ul><li>one continued</li><li>two</li></ul>\n"
        "<p>A paragraph over two lines:</p>\n"
        '<table><thead><tr><th>t</th></tr></thead><tbody><tr><td class="num">1</td></tr>'
        "</tbody></table>"
    )


def test_split_sections() -> None:
    title, intro, sections = split_sections("# T\n\nIntro.\n\n## A\n\ntext a\n## B\nb\n")
    assert (title, intro) == ("T", "Intro.")
    assert sections == [("A", "text a"), ("B", "b")]
