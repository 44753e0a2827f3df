from django.apps import AppConfig


class SegmentationConfig(AppConfig):
    name = "segmentation"
    verbose_name = "Segmentation"

    def ready(self):
        # Registers the tasks and connects segmentation.workers to Celery, in
        # every process: the web server enqueues jobs as the workers do.
        from segmentation import tasks  # noqa: F401

        # A deleted capture or run takes its stored files along.
        from segmentation.files import cleanup

        cleanup.connect()
