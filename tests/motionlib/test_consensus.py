"""The cuts a project learns from when several annotators reviewed a take: a cut at least
half of them made, at the median of their cuts (motionlib.consensus)."""

from unittest import TestCase

from motionlib.consensus import consensus_cuts

TOL = 120  # 1 s at 120 fps


class ConsensusTestCase(TestCase):
    def test_one_review_gives_its_own_cuts(self):
        self.assertEqual(consensus_cuts([[300, 100, 100]], TOL), [100, 300])

    def test_no_review_gives_no_cut(self):
        self.assertEqual(consensus_cuts([], TOL), [])

    def test_it_places_a_cut_all_made_at_the_median_of_their_frames(self):
        self.assertEqual(consensus_cuts([[100], [130], [110]], TOL), [110])

    def test_the_median_of_an_even_number_of_cuts_is_the_lower_middle_one(self):
        self.assertEqual(consensus_cuts([[100], [140], [120], [130]], TOL), [120])

    def test_one_under_cutting_annotator_among_three_removes_no_cut(self):
        truth = [500, 1500, 2500, 3500]
        self.assertEqual(consensus_cuts([truth, [t + 12 for t in truth], [1500]], TOL), truth)

    def test_one_over_cutting_annotator_among_three_adds_no_cut(self):
        truth = [500, 1500, 2500]
        over = [200, 500, 900, 1500, 2000, 2500, 3000]
        self.assertEqual(consensus_cuts([truth, truth, over], TOL), truth)

    def test_a_cut_half_of_the_reviews_made_is_kept(self):
        self.assertEqual(consensus_cuts([[500, 1500], [500]], TOL), [500, 1500])
        self.assertEqual(consensus_cuts([[500, 1500], [500], [500, 1510], [500]], TOL), [500, 1500])

    def test_cuts_further_apart_than_the_tolerance_are_different_cuts(self):
        self.assertEqual(consensus_cuts([[500], [621], [700]], TOL), [621])
        self.assertEqual(consensus_cuts([[500], [700]], TOL), [500, 700])

    def test_each_cut_of_a_review_supports_one_consensus_cut(self):
        # Two close cuts of one review are not two votes for one cut of another's.
        self.assertEqual(consensus_cuts([[500, 560], [530], [530]], TOL), [530])
        self.assertEqual(consensus_cuts([[500, 560], [505, 565], [900]], TOL), [500, 560])

    def test_it_does_not_depend_on_the_order_of_the_reviews(self):
        reviews = [[100, 700, 1400], [130, 1390], [90, 720, 2000]]
        expected = consensus_cuts(reviews, TOL)
        self.assertEqual(expected, [100, 700, 1390])
        self.assertEqual(consensus_cuts(reviews[::-1], TOL), expected)
        self.assertEqual(consensus_cuts(reviews[1:] + reviews[:1], TOL), expected)


class RefereeTestCase(TestCase):
    """Two annotators who disagree tie; a referee that belongs to neither (the project's
    current model on the take) settles the tie (issue 48, item 3)."""

    truth = [500, 1500, 2500]
    over = [200, 500, 1000, 1500, 2000, 2500, 3000]

    def test_an_over_cutter_beside_one_honest_annotator_adds_no_cut_the_referee_did_not_propose(self):
        self.assertEqual(consensus_cuts([self.truth, self.over], TOL, referee=[510, 1490, 2520]), self.truth)

    def test_an_under_cutter_beside_one_honest_annotator_removes_no_cut_the_referee_proposed(self):
        self.assertEqual(consensus_cuts([self.truth, []], TOL, referee=[510, 1490, 2520]), self.truth)

    def test_the_referee_never_outvotes_an_annotator(self):
        # One review: its own cuts, whatever the referee proposes.
        self.assertEqual(consensus_cuts([self.truth], TOL, referee=[]), self.truth)
        # Three reviews: a cut one of them made stays out with the referee behind it.
        self.assertEqual(consensus_cuts([self.truth, self.truth, self.over], TOL, referee=self.over), self.truth)
        # A cut both annotators made stays in without it.
        self.assertEqual(consensus_cuts([self.truth, self.truth], TOL, referee=[]), self.truth)

    def test_a_cut_is_placed_among_the_annotators_cuts_never_at_the_referees(self):
        self.assertEqual(consensus_cuts([[500], []], TOL, referee=[400]), [500])
