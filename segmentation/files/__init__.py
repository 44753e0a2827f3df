"""Files: capture originals and derived files in Django's storage, the parsed-take cache
beside them, and library clips written out as files.

- ``storage``: reading and writing capture files, reading a capture's take;
- ``takecache``: parsed takes kept beside their originals for retraining;
- ``exports``: library clips as BVH, FBX, glTF, C3D or CSV, and zip archives of them.
"""
