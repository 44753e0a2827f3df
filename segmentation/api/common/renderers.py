"""Renderers for answers that are not JSON."""

import json

from rest_framework.renderers import BaseRenderer


class BinaryRenderer(BaseRenderer):
    """Lets a client that asks for ``application/octet-stream`` reach a view whose success
    is raw bytes (the view answers with its own streaming response). Anything else the
    view answers with this renderer, an error's detail, is written as JSON, which the
    client reads as it reads every other error."""

    media_type = "application/octet-stream"
    format = "bin"
    charset = None
    render_style = "binary"

    def render(self, data, accepted_media_type=None, renderer_context=None):
        if isinstance(data, bytes):
            return data
        return json.dumps(data).encode()
