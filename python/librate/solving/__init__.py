"""The numerical solving layer: the continuation driver shared by every family in librate."""
