"""designkit.export."""
