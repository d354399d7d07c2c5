"""Exceptions raised by nsgraph: the C++ library's error tree (nsg::Error), each message
naming the file, the record and what was expected (also as attributes)."""


class Error(Exception):
    """Base of every nsgraph error. ``file``, ``record`` and ``expected`` are the parts of
    the message ("" when not known)."""

    file = ""
    record = ""
    expected = ""


class ParseError(Error, ValueError):
    """Malformed input: not JSON, not a TIFF, a corrupt or truncated tar."""


class DataError(Error, ValueError):
    """Well-formed but inconsistent input: an edge to a missing node, a tile count that
    differs from the manifest."""


class ConfigError(Error, ValueError):
    """A bad argument: an unknown split or modality, a parameter out of range."""


class IoError(Error, OSError):
    """The file system: a missing or unreadable file (e.g. a folder without manifest.json)."""


class InternalError(Error, RuntimeError):
    """A broken invariant of nsgraph itself (please report it)."""


class SubmissionError(Error, ValueError):
    """A submission with problems, as ``nsgraph score`` / ``validate --submission`` report
    them (the CLI's exit 1). ``issues`` is a list of {severity, check, subject, message}."""

    def __init__(self, message, issues=()):
        super().__init__(message)
        self.issues = list(issues)
