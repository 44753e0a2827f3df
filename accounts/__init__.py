"""Accounts: signing in (throttled), API tokens that expire and can be revoked."""
