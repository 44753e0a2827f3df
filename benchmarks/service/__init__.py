"""The service end to end, run as `make up` runs it (or on PostgreSQL where a benchmark
says so): uploads to cuts, review requests, bulk import, retraining, the soak."""
