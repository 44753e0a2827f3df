"""The API's plumbing, which the views share and which imports no view:

- ``errors``: the one translator from domain errors to HTTP responses;
- ``parsers``: bounded JSON bodies; ``params``: query and body parameters checked;
- ``pathids``: path ids out of range answered 404 before any view;
- ``heavy``: answers of stored data cached and limited in concurrency;
- ``schema``: checks of the OpenAPI schema;
- ``serializers``: the JSON shapes, one module per noun.
"""
