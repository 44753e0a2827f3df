"""JSON shapes of comments on a review: a comment as answered, and a new one."""

from rest_framework import serializers

from segmentation.api.common.serializers.base import Text
from segmentation.limits import text_limit
from segmentation.models import Comment
from segmentation.models.comments import ANCHORS


class CommentSerializer(serializers.Serializer):
    id = serializers.IntegerField()
    review = serializers.IntegerField(source="review_id")
    annotator = serializers.CharField(source="review.annotator.username",
                                      help_text="whose review the thread is on")
    author = serializers.SerializerMethodField()
    parent = serializers.IntegerField(source="parent_id", allow_null=True)
    anchor = serializers.ChoiceField(choices=ANCHORS)
    cut = serializers.IntegerField(source="cut_id", allow_null=True)
    frame = serializers.SerializerMethodField(help_text="where the thread is now: its cut's "
                                              "frame, or the frame it was written at")
    text = serializers.CharField()
    created_at = serializers.DateTimeField()
    resolved = serializers.SerializerMethodField()
    resolved_by = serializers.SerializerMethodField()

    def get_author(self, c) -> str | None:
        return c.author.username if c.author else None

    def get_frame(self, c) -> int:
        return c.anchor_frame()

    def get_resolved(self, c) -> bool:
        return c.resolved_at is not None

    def get_resolved_by(self, c) -> str | None:
        return c.resolved_by.username if c.resolved_by else None


class NewCommentSerializer(serializers.Serializer):
    """A thread on one of ``frame``, ``cut`` (a cut id) or ``segment`` (an index), or a
    reply (``parent``)."""

    text = Text(text_limit(Comment, "text"))
    frame = serializers.IntegerField(required=False, allow_null=True)
    cut = serializers.IntegerField(required=False, allow_null=True)
    segment = serializers.IntegerField(required=False, allow_null=True)
    parent = serializers.IntegerField(required=False, allow_null=True)


class ResolveSerializer(serializers.Serializer):
    resolved = serializers.BooleanField()
