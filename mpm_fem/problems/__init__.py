"""Problem set-ups: settings with their defaults in one place, initial particles, exact solutions."""
