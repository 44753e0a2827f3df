"""Similar clips: segment descriptors, the per-project vector index, and the searches
that read them ("find similar" and label suggestions)."""
