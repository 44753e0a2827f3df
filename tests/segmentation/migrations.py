"""A test case that moves the database to a migration, builds rows in that schema, and
leaves the database at the latest migration again."""

from django.db import connection
from django.db.migrations.executor import MigrationExecutor
from django.test import TransactionTestCase


class MigrationTestCase(TransactionTestCase):
    def migrate(self, targets):
        """Migrate to ``targets`` ([(app, migration)]); the historical apps there."""
        executor = MigrationExecutor(connection)
        executor.loader.build_graph()
        executor.migrate(targets)
        return executor.loader.project_state(targets).apps

    def tearDown(self):
        self.migrate(MigrationExecutor(connection).loader.graph.leaf_nodes())
