"""Ids in API paths, held to the 64-bit range of a database integer in one place.

A path like ``/api/captures/18446744073709551623/`` names an id no row can have; it is
answered 400 naming the path parameter before any view looks it up, instead of reaching
a database driver that cannot hold the number.
"""

from django.http import JsonResponse

from segmentation.api.common.params import INT_RANGE


class PathIdMiddleware:
    """Refuse an API request whose whole-number path parameter is beyond 64 bits."""

    def __init__(self, get_response):
        self.get_response = get_response

    def __call__(self, request):
        return self.get_response(request)

    def process_view(self, request, view_func, view_args, view_kwargs):
        if not request.path.startswith("/api/"):
            return None
        for name, value in view_kwargs.items():
            number = _whole_number(value)
            if number is not None and not INT_RANGE[0] <= number <= INT_RANGE[1]:
                shown = str(value) if len(str(value)) <= 40 else f"{str(value)[:20]}... " \
                                                                  f"({len(str(value))} digits)"
                message = f"{name}: {shown} is not an id (ids are at most {INT_RANGE[1]})"
                return JsonResponse({"detail": message, name: [message]}, status=400)
        return None


def _whole_number(value):
    if isinstance(value, int) and not isinstance(value, bool):
        return value
    if isinstance(value, str) and value.isascii() and value.isdigit() and len(value) < 4000:
        return int(value)
    return None
