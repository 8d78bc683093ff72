"""The exceptions of thzmap, and how a C error becomes one.

The library reports an error as a status and a one-line message that names the file
and either line:column (JSON syntax, CSV files) or the JSON path (content). A bad
scene becomes SceneError with those parts as attributes; every other failure Error.
"""
import re

from . import _lib


class Error(Exception):
    """A failure reported by libthzmap. `status` is the library's status name
    ("bad input", "input/output error", ...), `message` its one-line message."""

    def __init__(self, message, status=None):
        super().__init__(message)
        self.message = message
        self.status = status


class SceneError(Error):
    """A scene the library refuses. `file` is the scene file (or the label of a scene
    made from a dict), `path` the JSON path such as "objects[2].temperature_k" (None for
    a syntax error), `line` and `column` the position of a syntax error (else None),
    `reason` the message without file and path."""

    def __init__(self, message, file=None, path=None, line=None, column=None, reason=None):
        super().__init__(message, "bad input")
        self.file = file
        self.path = path
        self.line = line
        self.column = column
        self.reason = reason if reason is not None else message


class CancelledError(Error):
    """The run was cancelled by the progress callback; nothing was returned or written."""

    def __init__(self, message="cancelled"):
        super().__init__(message, "cancelled")


class OutOfMemoryError(Error, MemoryError):
    """The library ran out of memory (the run was refused or stopped; nothing leaked)."""


class ArgumentError(Error, ValueError):
    """An argument of a thzmap function is wrong (checked before the library is called)."""


# A JSON path as the loader writes it: a key, then ".key" or "[index]" steps (keys of
# materials may hold spaces), up to the ": " that starts the reason.
_PATH = re.compile(r"^([A-Za-z_][\w-]*(?:\.[^:]*?|\[\d+\])*): (.*)$", re.S)
_POSITION = re.compile(r"^(\d+)(?::(\d+))?: (.*)$", re.S)


_KEY = re.compile(r"^[A-Za-z_][\w-]*$")


def _path_in(doc, path):
    """Whether `path` (a loader's JSON path, "a.b[2].c") names a value of doc, or a key
    its last object lacks (a "missing key" error). Keys with '.', '[' or ': ' in them
    (materials may be named so) are matched against doc's own keys."""
    node, rest = doc, "." + path
    while rest:
        if rest.startswith("[") and isinstance(node, list):
            m = re.match(r"\[(\d+)\]", rest)
            if not m or int(m.group(1)) >= len(node):
                return False
            node, rest = node[int(m.group(1))], rest[m.end():]
            continue
        if not rest.startswith(".") or not isinstance(node, dict):
            return False
        rest = rest[1:]
        # the longest of node's keys that the path continues with
        keys = [k for k in node if rest == k or rest.startswith(k + ".") or
                rest.startswith(k + "[")]
        if keys:
            k = max(keys, key=len)
            node, rest = node[k], rest[len(k):]
            continue
        return bool(_KEY.match(rest))  # the last key, missing from the document
    return True


def _split_with(doc, rest):
    """(path, reason) where the text before one of rest's ": " is a path of doc (the
    longest such), or None."""
    best = None
    for m in re.finditer(r": ", rest):
        if _path_in(doc, rest[:m.start()]):
            best = (rest[:m.start()], rest[m.end():])
    return best


def scene_error(message, label, doc=None):
    """SceneError from the library's message about a scene labelled `label`; `doc`, the
    scene's JSON as a dict where known, tells the JSON path from the reason when a key
    holds ": " itself."""
    file = None
    rest = message
    if label is not None and message.startswith(label + ":"):
        file, rest = label, message[len(label) + 1:]
    else:  # a file other than the label, e.g. "dir/x.csv:3: ..."
        m = re.match(r"^([^:\s][^:]*):(?=\s|\d)", message)
        if m:
            file, rest = m.group(1), message[m.end():]
    line = column = path = None
    m = _POSITION.match(rest)
    if m:
        line = int(m.group(1))
        column = int(m.group(2)) if m.group(2) else None
        reason = m.group(3)
    else:
        rest = rest[1:] if rest.startswith(" ") else rest
        split = _split_with(doc, rest) if isinstance(doc, dict) else None
        m = _PATH.match(rest)
        if split:
            path, reason = split
        elif m:
            path, reason = m.group(1), m.group(2)
        else:
            reason = rest
    return SceneError(message, file=file, path=path, line=line, column=column, reason=reason)


def from_status(status, message, scene_label=None):
    """The exception for a failed call: SceneError for bad input about a scene (when
    `scene_label` names it: a position or JSON path in it, or the message about the file
    itself, which cannot be opened), CancelledError, else Error."""
    if status == _lib.ERR_CANCELLED:
        return CancelledError(message or "cancelled")
    if status == _lib.ERR_NOMEM:
        return OutOfMemoryError(message, "out of memory")
    if status == _lib.ERR_INPUT and scene_label is not None:
        err = scene_error(message, scene_label)
        if err.path is not None or err.line is not None or err.file == scene_label:
            return err
    return Error(message, _lib.text(_lib.lib.thz_status_name(status)))
