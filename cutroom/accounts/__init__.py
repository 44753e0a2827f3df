"""Only the sign-in backend's former path (``backends``); the accounts app is ``accounts``."""
