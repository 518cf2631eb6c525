"""Errors the CLI turns into one clear message and an exit code, never a traceback."""
from __future__ import annotations


class UserError(Exception):
    """A problem with the user's input (file, column, key, value). ``exit_code`` 2 by convention."""

    def __init__(self, message: str, exit_code: int = 2):
        super().__init__(message)
        self.exit_code = exit_code


class BuildError(Exception):
    """A generated part or model failed a check (exit code 1): names the part and the check."""

    def __init__(self, message: str, exit_code: int = 1):
        super().__init__(message)
        self.exit_code = exit_code
