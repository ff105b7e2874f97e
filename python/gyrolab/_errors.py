"""gyrolab's exception, defined in Python so that it pickles (a spawn pool, a Dask worker sends
it back to the parent with its message and location)."""

from __future__ import annotations

from typing import Any, Dict, Optional, Tuple, Type


def _rebuild(cls: Type[BaseException], args: Tuple[Any, ...], state: Dict[str, Any]) -> BaseException:
    """Unpickles an :class:`Error` (or a subclass) with its arguments and attributes."""
    e = cls.__new__(cls)
    e.args = args
    e.__dict__.update(state)
    return e


class Error(ValueError):
    """A gyrolab evaluation failed: bad data or options. ``str(e)`` is the located message;
    the location is also in attributes (``None`` where it does not apply): ``file`` (the
    file or record), ``line`` (1-based line of the file), ``column`` (column name or
    1-based index), ``keyword`` (the keyword argument at fault)."""

    def __init__(
        self,
        message: str = "",
        *,
        file: Optional[str] = None,
        line: Optional[int] = None,
        column: Optional[str] = None,
        keyword: Optional[str] = None,
    ) -> None:
        super().__init__(message)
        self.message = message
        self.file = file
        self.line = line
        self.column = column
        self.keyword = keyword

    def __reduce__(self) -> Any:
        return (_rebuild, (type(self), self.args, dict(self.__dict__)))


Error.__module__ = "gyrolab"
