"""The exceptions of cmc33: one class per cmc33::Status of the C++ library.

Every one derives from :class:`cmc33.Error` and from the built-in exception a Python user would
expect (``ValueError`` for bad arguments and bad files, ``OSError`` when the operating system
refuses, ``MemoryError`` for sizes that do not fit), so ``except ValueError`` keeps working. The
message is the library's: one line naming what is wrong and what was expected.
"""

from __future__ import annotations


class Error(Exception):
    """Base class of every error the cmc33 library reports. ``status`` names the library's
    cmc33::Status ("invalid_argument", "io_error", ...)."""

    status = "internal"


class InvalidArgumentError(Error, ValueError):
    """An argument out of its range (the caller's fault)."""

    status = "invalid_argument"


class FileError(Error, OSError):
    """The operating system refused: a missing file or folder, no permission, a full disk."""

    status = "io_error"


class TruncatedFileError(Error, ValueError):
    """A file holds fewer bytes than its header declares."""

    status = "truncated_file"


class FormatError(Error, ValueError):
    """A header or payload that does not follow its format."""

    status = "bad_format"


class UnsupportedFormatError(Error, ValueError):
    """A valid but unsupported variant of a format (an encoding, a type, an extension)."""

    status = "unsupported_format"


class NonFiniteError(Error, ValueError):
    """NaN or infinity in the samples or the parameters."""

    status = "non_finite"


class TooLargeError(Error, MemoryError):
    """Sizes that overflow, or more memory than can be allocated."""

    status = "too_large"


class CancelledError(Error):
    """The work was stopped because the progress callback returned False."""

    status = "cancelled"


class InternalError(Error, RuntimeError):
    """A broken invariant: a bug in cmc33 (please report it with the input)."""

    status = "internal"


#: cmc33::Status name -> exception class (the compiled module raises through this table).
STATUS_ERRORS = {cls.status: cls for cls in (InvalidArgumentError, FileError, TruncatedFileError, FormatError,
                                             UnsupportedFormatError, NonFiniteError, TooLargeError, CancelledError,
                                             InternalError)}
