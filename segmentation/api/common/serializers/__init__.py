"""JSON shapes of docs/api.md, one module per noun. Output serializers mirror the records;
input serializers check the request's shape, and the services check its meaning."""
