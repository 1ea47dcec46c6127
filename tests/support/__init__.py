"""What the tests share: helpers, strategies, reference checkers, corruptions and mutants, golden cases.

And for junctions of 4 to 8 legs: ``G_k`` and the retraction rebuilt from the text (``star_spec``),
the continuity cases of the planner (``continuity``), scenarios of k legs (``star_scenarios``).
"""
