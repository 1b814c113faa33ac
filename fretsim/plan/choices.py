"""A plan's record: every decision as a :class:`Choice` (value and reason), and its warnings."""
from __future__ import annotations

from dataclasses import dataclass, field
from typing import Any


@dataclass(frozen=True)
class Choice:
    """One decision of the plan: the case key it fills, its value (as written in the filled case) and why."""

    key: str
    value: Any
    reason: str
    given: bool = False  # True when the case set it itself
    error: float = 0.0  # the relative difference from the fuller model this choice accepted (auto's simplifications)


@dataclass
class Plan:
    choices: list = field(default_factory=list)
    warnings: list = field(default_factory=list)

    def add(self, choice: Choice) -> Any:
        """Record a choice; a later choice for the same key replaces the earlier one (one line per key)."""
        self.choices = [c for c in self.choices if c.key != choice.key] + [choice]
        return choice.value

    def copy(self) -> "Plan":
        return Plan(list(self.choices), list(self.warnings))


def show(value: Any) -> str:
    """A choice's value as ``check`` and the notes print it."""
    if isinstance(value, tuple):
        return "[" + ", ".join(f"{v:.4g}" if isinstance(v, float) else str(v) for v in value) + "]"
    return f"{value:.4g}" if isinstance(value, float) else str(value)
