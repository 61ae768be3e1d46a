r"""One escape per sink, for text that comes from data or paths (channel names, file names, topics).

A name read from a file is shown, never obeyed: every writer passes such text through the
escape of the place it goes to, and each escape lives here, once.

* the terminal, :func:`terminal`: control and format characters (``\x1b[2J``, CR, U+202E
  right-to-left override, line breaks) written as Python escapes; :func:`terminal_lines` keeps
  the line breaks of a multi-line text and escapes the rest;
* YAML, :func:`yaml_comment` and :func:`yaml_entry`: a comment is one line that ends where
  it should (a name holding a newline, ``---`` or ESC adds no key and keeps the file
  parseable), a value is quoted and escaped by PyYAML on one line;
* HTML, :func:`html_text`: ``&``, ``<``, ``>`` and quotes as entities;
* matplotlib, :func:`figure_text`: drawn literally, never as mathtext (``$`` escaped), with
  the control characters escaped as on the terminal.

Only the standard library: every layer may use it.
"""

from __future__ import annotations

import html
from typing import Any

__all__ = ["figure_text", "html_text", "terminal", "terminal_lines", "yaml_comment", "yaml_entry"]


def terminal(text: object) -> str:
    r"""``text`` with control and format characters written as escapes, safe to print on a terminal.

    Names read from a file (a header cell holding ``\x1b[2J``, a U+202E override) are shown,
    never obeyed; a line break in a name is shown as ``\n``.

    >>> terminal("gx\x1b[31m"), terminal("a\nb"), terminal("x\u202ey")
    ('gx\\x1b[31m', 'a\\nb', 'x\\u202ey')
    """
    text = str(text)
    if text.isprintable():
        return text
    return "".join(c if c.isprintable() else c.encode("unicode_escape", "backslashreplace").decode("ascii")
                   for c in text)


def terminal_lines(text: object) -> str:
    r"""A multi-line text (a table, a report) for the terminal: its line breaks (``\n``) kept,
    every other control or format character escaped as :func:`terminal` does.

    >>> terminal_lines("a\x1b[2J\nb\rc")
    'a\\x1b[2J\nb\\rc'
    """
    return "\n".join(terminal(line) for line in str(text).split("\n"))


def yaml_comment(text: object) -> str:
    r"""A YAML comment line (``# ...``) of ``text``: one line whatever it holds.

    Every line break YAML knows (LF, CR, NEL, U+2028, U+2029) and every character YAML refuses
    (ESC, other controls) is escaped as on the terminal, so the comment ends at its own line end.

    >>> yaml_comment("from gx\naccelerometer_noise_density: 5.0")
    '# from gx\\naccelerometer_noise_density: 5.0'
    """
    return f"# {terminal(text)}"


def yaml_entry(key: str, value: Any) -> str:
    """``key: value`` on one line: a string value plain when PyYAML writes it so on one line, else
    double-quoted with its escapes (a line break, ESC, ``---``); other values as PyYAML writes them.

    >>> yaml_entry("rostopic", "/imu0"), yaml_entry("rostopic", "/imu0\\n---"), yaml_entry("rate", 200.0)
    ('rostopic: /imu0', 'rostopic: "/imu0\\\\n---"', 'rate: 200.0')
    """
    import yaml

    text = yaml.safe_dump({key: value}, default_flow_style=False, width=float("inf")).strip()
    if isinstance(value, str) and "\n" in text:
        text = f"{key}: " + yaml.safe_dump(value, default_style='"', width=float("inf")).strip()
    return text


def html_text(text: object) -> str:
    """``text`` for an HTML page or a notebook: ``&``, ``<``, ``>`` and quotes as entities.

    >>> html_text("gyro<img src=x onerror=alert(1)>")
    'gyro&lt;img src=x onerror=alert(1)&gt;'
    """
    return html.escape(str(text))


def figure_text(text: object) -> str:
    r"""``text`` drawn literally by matplotlib: ``$`` escaped (no mathtext), controls escaped.

    For labels made of names read from data; a title the user gives is drawn as given.

    >>> figure_text(r"gyro $\undefinedcommand$")
    'gyro \\$\\undefinedcommand\\$'
    """
    return terminal(text).replace("$", r"\$")
