"""JSON shapes of agreement: how a capture's submitted reviews agree, and how a label's
segments overlap."""

from rest_framework import serializers

from segmentation.api.common.serializers.base import UserRefSerializer


class AgreementReviewSerializer(serializers.Serializer):
    id = serializers.IntegerField()
    annotator = UserRefSerializer()
    cuts = serializers.IntegerField(help_text="How many cuts it keeps")
    submitted_at = serializers.DateTimeField(allow_null=True)


class PairSideSerializer(serializers.Serializer):
    review = serializers.IntegerField()
    annotator = serializers.CharField()


class PairSerializer(serializers.Serializer):
    a = PairSideSerializer()
    b = PairSideSerializer()
    precision = serializers.FloatField(allow_null=True)
    recall = serializers.FloatField(allow_null=True)
    f1 = serializers.FloatField(allow_null=True)
    matched = serializers.IntegerField()
    kappa = serializers.FloatField(allow_null=True)


class LabelMeasureSerializer(serializers.Serializer):
    method = serializers.ChoiceField(choices=["cohen_kappa", "krippendorff_alpha"], allow_null=True)
    value = serializers.FloatField(allow_null=True)


class LabelOverlapSerializer(serializers.Serializer):
    label = serializers.CharField()
    overlap = serializers.FloatField(allow_null=True)
    frames = serializers.IntegerField()


class AgreementSerializer(serializers.Serializer):
    """Agreement of a capture's submitted reviews (measures null where undefined)."""

    capture = serializers.IntegerField()
    tolerance_s = serializers.FloatField()
    n_reviews = serializers.IntegerField()
    reviews = AgreementReviewSerializer(many=True)
    pairs = PairSerializer(many=True)
    boundary_f1 = serializers.FloatField(allow_null=True)
    labels = LabelMeasureSerializer()
    alpha = serializers.FloatField(allow_null=True)
    per_label = LabelOverlapSerializer(many=True)
