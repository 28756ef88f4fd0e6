"""designkit.recognition."""
