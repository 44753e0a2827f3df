"""Reading capture files: the formats' readers against each other and against the BVH of
the same take, and what hostile files cost to read or refuse."""
