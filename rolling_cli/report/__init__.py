"""What a user sees: the on-screen summary and the figures. Reads results and files."""
