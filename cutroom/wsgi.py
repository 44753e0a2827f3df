import gc
import os

from django.core.wsgi import get_wsgi_application
from django.urls import get_resolver

os.environ.setdefault("DJANGO_SETTINGS_MODULE", "cutroom.settings")
application = get_wsgi_application()

# Load the URLconf (and with it the API, numpy, scipy and the segmenters) now, then move
# everything loaded so far out of the collector's reach: without this, every full
# collection rescans ~170,000 long-lived objects and stalls a request by ~200 ms.
get_resolver().check()
gc.collect()
gc.freeze()
