"""What a person reads: one beta on screen (Dundurs'), one short line per effect, the plot's bands
in its legend (issue #20 item 6)."""

from __future__ import annotations

import re

from helpers import dissimilar, solve
from rolling_cli.report.summary import WIDTH, summary


def test_one_beta_on_screen_named_dundurs(tmp_path):
    """The effects and the Hertz line show the same beta, Dundurs' (half the seed paper's), named
    as such; the file keeps the seed's value under its own name."""
    result = solve(dissimilar(**{"discretization.contact_elements": 40}))
    text = summary(result)
    shown = {float(v) for v in re.findall(r"beta \(Dundurs\) = (-?[0-9.e+-]+)", text)}
    assert len(shown) == 1
    dundurs = result.attributes["beta_dundurs"]
    assert abs(shown.pop() - dundurs) <= 5e-4 * abs(dundurs)  # 4 significant digits on screen
    assert not re.search(r"beta = ", text)  # no unnamed beta
    assert abs(result.attributes["beta_seed"] - 2.0 * dundurs) <= 1e-12 * abs(dundurs)  # the seed's, in the file


def test_effects_one_line_each_and_no_wide_lines():
    result = solve(dissimilar(**{"discretization.contact_elements": 40}))
    lines = summary(result, output="some/where.h5").splitlines()
    first = next(i for i, line in enumerate(lines) if line.startswith("  effects"))
    effect_lines = [lines[first]] + [line for line in lines[first + 1 :] if line.startswith(" " * 17) and ": " in line][
        :4
    ]
    names = [line.strip().removeprefix("effects").strip().split(":")[0] for line in effect_lines]
    assert names[:4] == ["coupling", "tangential", "normal", "influence"]
    assert max(len(line) for line in lines) <= WIDTH


def test_result_plot_has_band_legend(tmp_path):
    from rolling_cli.files.io_hdf5 import write_result
    from rolling_cli.report.plot import plot_file

    path = tmp_path / "r.h5"
    write_result(solve(dissimilar(**{"discretization.contact_elements": 40})), path)
    fig = plot_file(str(path), str(tmp_path / "r.png"))
    labels = [text.get_text() for text in fig.axes[0].get_legend().get_texts()]
    assert "slip zone" in labels and "adhesion zone" in labels
