"""JSON shapes of a capture's gold version, as the adjudication page and a refused
edit (409) answer it."""

from rest_framework import serializers

from segmentation.api.common.serializers.base import DetailSerializer


class SpanSerializer(serializers.Serializer):
    start = serializers.IntegerField()
    stop = serializers.IntegerField()
    label = serializers.CharField(allow_null=True)


class GoldBodySerializer(serializers.Serializer):
    """The capture's gold version as stored."""

    version = serializers.IntegerField()
    cuts = serializers.ListField(child=serializers.IntegerField())
    labels = serializers.ListField(child=serializers.CharField(allow_null=True))
    segments = SpanSerializer(many=True)
    adjudicator = serializers.CharField(allow_null=True)
    source_review = serializers.IntegerField(allow_null=True)
    updated_at = serializers.DateTimeField()


class StaleGoldSerializer(DetailSerializer):
    """409: the gold version changed since the one the edit was based on."""

    gold = GoldBodySerializer(allow_null=True)


def gold_body(gold):
    if gold is None:
        return None
    segments = gold.segments()
    return {
        "version": gold.version, "cuts": gold.cuts, "labels": [c for _, _, c in segments],
        "segments": [{"start": a, "stop": b, "label": c} for a, b, c in segments],
        "adjudicator": gold.adjudicator.username if gold.adjudicator else None,
        "source_review": gold.source_review_id, "updated_at": gold.updated_at,
    }
