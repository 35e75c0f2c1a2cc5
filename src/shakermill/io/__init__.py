"""Files of a run: run folders written atomically and read back."""
