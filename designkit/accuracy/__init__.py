"""designkit.accuracy."""
