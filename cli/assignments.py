"""The grammar of ``--set KEY=V1,V2,...`` (``adhcontact sweep``): a dotted
TOML key and comma-separated TOML values, parsed into the ``(key, [values])``
settings that :class:`adhesive_contact.studies.Sweep` takes."""

import re
import tomllib

#: the deepest nesting of brackets in a value given to --set
MAX_VALUE_DEPTH = 16
_BARE = re.compile(r"[A-Za-z_][A-Za-z0-9_-]*")


class AssignmentError(ValueError):
    """A malformed ``--set``: ``key`` names it (``"set"`` or ``"set KEY"``),
    ``message`` says what is wrong and what is allowed."""

    def __init__(self, key, message):
        self.key, self.message = key, message
        super().__init__(f"{key}: {message}")


def split_values(text):
    """Split ``"1e2,1e3"`` at the commas outside brackets and quotes."""
    parts, depth, quote, start = [], 0, None, 0
    for i, ch in enumerate(text):
        if quote:
            if ch == quote:
                quote = None
        elif ch in "\"'":
            quote = ch
        elif ch in "[{":
            depth += 1
        elif ch in "]}":
            depth -= 1
        elif ch == "," and depth == 0:
            parts.append(text[start:i])
            start = i + 1
    parts.append(text[start:])
    return [p.strip() for p in parts]


def parse_value(text):
    """A TOML value (``1e3``, ``10``, ``true``, ``"gauss"``, ``[8, 4]``); a bare
    word that is not TOML (``gauss``) is taken as a string.

    Raises ValueError naming the text when it is neither."""
    depth = level = 0
    quote = None
    for char in text:   # before the parser, which recurses per bracket
        if quote:
            quote = None if char == quote else quote
        elif char in "\"'":
            quote = char
        else:
            level += (char in "[{") - (char in "]}")
            depth = max(depth, level)
    if depth > MAX_VALUE_DEPTH:
        raise ValueError(f"a value nested {depth} deep (at most {MAX_VALUE_DEPTH} levels of "
                         "brackets)")
    try:
        return tomllib.loads(f"v = {text}")["v"]
    except tomllib.TOMLDecodeError:
        if _BARE.fullmatch(text):
            return text
        raise ValueError(f"{text!r} is not a TOML value (a number, true/false, "
                         "a quoted string or an array)") from None


def parse_assignment(text):
    """``"KEY=V1,V2,..."`` -> (key, [values]) with TOML values (:func:`parse_value`).

    Raises :class:`AssignmentError` (key ``"set"``, or ``"set KEY"``) for a
    malformed one."""
    key, sep, values = text.partition("=")
    key = key.strip()
    if not sep or not key or not values.strip():
        raise AssignmentError("set", f"{text!r}: expected KEY=V1,V2,... (a dotted TOML key, "
                         "comma-separated values)")
    if not all(part for part in key.split(".")):
        raise AssignmentError("set", f"{key!r}: empty part in the dotted key")
    parsed = []
    for item in split_values(values):
        try:
            parsed.append(parse_value(item))
        except ValueError as err:
            raise AssignmentError(f"set {key}", str(err)) from None
    return key, parsed
