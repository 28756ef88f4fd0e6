"""designkit.sweep."""
