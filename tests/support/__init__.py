"""What the tests share: helpers, strategies, reference checkers, corruptions and mutants, golden cases."""
