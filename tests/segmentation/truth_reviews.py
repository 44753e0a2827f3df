"""A submitted review at a synthetic take's true boundaries, for the tests of the label
model and its proposals (unit, integration and browser)."""

from motionlib import synth
from segmentation import services

SECONDS = 30.0


def review_to_the_truth(project, capture, user, seed, name=lambda action: action):
    """``user`` cuts ``capture`` (made with ``synth`` from ``seed``) at its true boundaries,
    labels each segment ``name(true action)``, adding the labels the project lacks, and
    submits. Returns the take's true segments."""
    _take, segments = synth.generate(seed=seed, fps=120.0, duration=SECONDS)
    for _, _, action in segments:
        if not project.labels.filter(name=name(action)).exists():
            services.do_add_label(project, name(action))
    review = services.get_or_create_review(capture, user)
    for cut in list(review.cuts.all()):
        services.do_change_cut(review, user, cut, review.version, fate="deleted")
    for start, _stop, _label in segments[1:]:
        services.do_insert_cut(review, user, start, review.version)
    for index, (_, _, action) in enumerate(segments):
        services.do_label_segment(review, user, index, name(action), review.version)
    services.do_submit_review(review, user, review.version)
    return segments
