"""designkit.query."""
