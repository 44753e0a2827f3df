"""The segment library: its list and its similar-clip search on a seeded library of a
million described segments (``million``, ``million_sqlite``), and the vector index
libraries the search was chosen among."""
