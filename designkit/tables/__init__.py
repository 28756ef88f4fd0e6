"""designkit.tables."""
