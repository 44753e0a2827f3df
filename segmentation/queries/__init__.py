"""Reads: what a request may see and the lists and summaries it shows. Nothing here
writes; workflows that change records are in ``segmentation.services``."""
