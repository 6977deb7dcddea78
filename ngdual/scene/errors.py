"""What a scene that cannot be solved raises: one error naming every offending field."""

from __future__ import annotations

from contextlib import contextmanager


class SceneError(ValueError):
    """A scene that cannot be solved; ``field`` names the offending entry.

    Several problems found together are one error: ``problems`` lists every
    ``(field, message)`` pair, ``field`` is the first of them and the message has one
    line per problem.
    """

    def __init__(self, field_name: str, message: str,
                 problems: list[tuple[str, str]] | None = None):
        self.problems = list(problems or [(field_name, message)])
        self.field = self.problems[0][0]
        if len(self.problems) == 1:
            text = f"{self.field}: {self.problems[0][1]}"
        else:
            text = (f"{len(self.problems)} problems in the scene:\n"
                    + "\n".join(f"  {f}: {m}" for f, m in self.problems))
        super().__init__(text)

    @property
    def fields(self) -> list[str]:
        """The fields of every problem, in the order found."""
        return [f for f, _ in self.problems]


class Problems:
    """Collects the :class:`SceneError` s of independent checks, to report them together."""

    def __init__(self):
        self.found: list[tuple[str, str]] = []

    @contextmanager
    def check(self):
        """Run the checks in the ``with`` block; a SceneError there is recorded, not raised."""
        try:
            yield
        except SceneError as err:
            self.found.extend(err.problems)

    def add(self, field_name: str, message: str) -> None:
        self.found.append((field_name, message))

    def run(self, check, *args, value: bool = False, **kwargs):
        """Call ``check``; on a SceneError record it and return False (None with ``value``),
        else return True (the result with ``value``)."""
        try:
            result = check(*args, **kwargs)
        except SceneError as err:
            self.found.extend(err.problems)
            return None if value else False
        return result if value else True

    def raise_any(self) -> None:
        if self.found:
            raise SceneError("", "", self.found)


class SceneTypeError(SceneError, TypeError):
    """An argument of the Python API of the wrong type (a :class:`SceneError` and a TypeError)."""
