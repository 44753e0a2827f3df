"""Database machinery below the models: nothing here knows a Cutroom record.

- ``statements``: querysets compiled once per shape, then run with new values only.
"""
