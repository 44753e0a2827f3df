import gc
import os

from django.core.wsgi import get_wsgi_application
from django.urls import get_resolver

os.environ.setdefault("DJANGO_SETTINGS_MODULE", "cutroom.settings")
django_application = get_wsgi_application()

from cutroom.lanes import LaneDispatcher  # noqa: E402  (needs the settings configured)

# Reads about long takes go to the bulk lane's server, when there is one (cutroom/lanes.py).
application = LaneDispatcher(django_application)

# Load the URLconf (and with it the API, numpy, scipy and the segmenters) now, then move
# everything loaded so far out of the collector's reach: without this, every full
# collection rescans ~170,000 long-lived objects and stalls a request by ~200 ms.
get_resolver().check()
gc.collect()
gc.freeze()
