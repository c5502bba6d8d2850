"""The numerical solving layer: continuation driver."""
