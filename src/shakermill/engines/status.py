"""Status codes every engine reports (negative: the run stopped early). Each engine adds its own beyond these."""

REACHED_STOP = 0
NOT_FINITE = -1
OVERLAP_TOO_LARGE = -2
# Checked between compiled calls, not in the loop: the run's budget (RunBudget.reason says which limit).
BUDGET_EXCEEDED = -4
