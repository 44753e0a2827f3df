"""Cutroom's own detector: multi-scale kernel novelty on a heading-invariant pose.

Why this design
---------------
An activity in a take (jumping jacks, squats, walking) is a *distribution* of poses that
repeats every second or so; a boundary is where that distribution changes. So:

1. Each frame becomes a pose vector that ignores where the performer stands and which
   way they face (joint positions relative to the root, heading removed, plus the root
   height, which separates squatting and jumping from standing), optionally with joint
   velocities so that holding a pose differs from moving through it. A take known only
   by a few angle channels (the subject-86 four-channel extracts) uses those angles.
2. The pose stream is averaged into short blocks (``rate_hz``) for speed.
3. At each instant the poses of the past window and the future window are compared
   with the maximum mean discrepancy (MMD) under a Gaussian kernel whose bandwidth is
   set by the median heuristic, at three window lengths from ``scale_min_s`` to
   ``scale_max_s`` (a window must span several repetitions of a periodic activity,
   about 1 Hz for most exercises, so that the poses inside one activity look alike from
   window to window; shorter windows also fire on brief changes inside an activity that
   annotators do not cut). MMD² is 0 for identical distributions and approaches 2 for
   disjoint ones, whatever the capture's units.
4. How many cuts. Peaks of the mean novelty curve at least ``threshold`` high, standing
   at least ``prominence`` above the higher of the valleys beside them, and at least
   ``min_segment_s`` from a higher peak become cuts; confidence ``q / (q + prominence)``
   grows with the peak's prominence q (0.5 at the setting), so candidates rank by
   evidence. Prominence, not height, is what tells a boundary from a wobble on the
   shoulder of a broad peak: most false peaks have a prominence near 0.

   a. *Support* (``support``, on; see "Support" below). A peak is dropped when the
      poses on its two sides are the same poses: for each pose of the 4 s after it
      (0.25 s around the peak left out), the squared kernel distance to the nearest pose
      of the 4 s before it, averaged, and the same the other way; below ``support``
      on both sides, nothing on either side is new. Windows holding a few cycles of a
      slow movement see its phases in other proportions from one instant to the next
      and peak there; at a boundary, one side takes poses the other never does. A peak
      that step c reads as a short activity is kept.

   b. *Short activities* (``short_activity``, off by default; see below). Optionally,
      a shoulder of a kept peak at most ``scale_min_s`` away also becomes a cut when
      windows of ``min_segment_s`` show prominent peaks at both
      (``short_activity_peaks``).
   c. *Short activities, by unmatched poses* (``short_unmatched``, on; see "Short
      activities: unmatched poses" below). Inside a repeating activity, some pose a
      cycle or two away always looks like the pose at hand; inside an activity shorter
      than about 3 s between two others, every pose ``min_segment_s`` to 8 s away
      belongs to the neighbours, and none does. Where the poses of a 1.2 s stretch near
      a kept peak are that unlike everything around them, the long windows have seen a
      short activity as one peak, and the peak becomes the activity's two sides, 1.25 s
      either side of the stretch's middle, each then placed by step 5
      (``unmatched_peaks``).
5. Placement, coarse to fine. The novelty peak locates a change only to within a
   block and a window; an annotator cuts at "the moment the motion changes": the end
   of the last movement of the old activity, where the body is momentarily still, or,
   after a pause, where the next activity sets off. So each cut is re-estimated in
   four steps (``place_stages``), the first three at most ``refine_s`` from the
   previous estimate:

   a. *Split.* Over ``±scale_min_s`` around the peak (never past half-way to a
      neighbouring cut), the split that minimises the within-segment variance of the
      poses in the kernel's feature space (the kernel change-point cost, same kernel as
      the novelty) on 30 Hz block means: the best two-segment fit of that stretch.
   b. *Turning point.* The cut moves to the nearest local minimum of the pose speed
      (poses low-passed at 3 Hz, native frame rate): the split locates the change to
      within a movement cycle, and between two cycles the body turns.
   c. *Pause.* If the performer really stops nearby (the 1 Hz speed falls below half
      its typical value around the cut), the cut moves to that pause (``settle_frame``).
   d. *Onset* (``onset``). If the cut then lies in a pause of at most 3 s after which
      the next activity moves at its typical speed, it moves to the end of the pause,
      the onset of the next activity, which is where annotators of the mocap6 and
      subject-86 labels cut (``onset_frame``); a long still stretch, or one followed by
      slow motion (idling), is an activity of its own and keeps its cut.

How the settings were chosen, and how each choice scores out of sample
----------------------------------------------------------------------
Every setting of ``tuning.GRID`` (windows, threshold, prominence, minimum segment,
onset, the unmatched-poses step, the support test; 2,560 combinations of principled
options) was scored on all 11 labelled takes under ``shared/data`` (13_29 BVH, 13_30 and
86_01 AMC, and the eight subject-86 four-channel takes, 86_01's counted as the same take
as its AMC), and the defaults are the combination with the best mean F1 at 1 s (ties:
fewer edits per true cut): mean F1@1 s 0.992 and 0.296 edits per true cut on those takes
(in-sample). Scored leave-one-take-out, i.e. each take with the combination chosen
without it (``python -m motionlib bench-quality --loo``), that choice gets mean F1@1 s
0.971 and 0.367 edits per true cut (before the support test 0.957 and 0.406; the earlier
defaults, threshold 0.25 and no prominence test: 0.862 and 0.60, chosen on 3 takes).
Each option with the others still chosen without the take scored, mean F1@1 s / edits
per true cut:

===============  ========================================================
windows          1.5-3 s 0.871/0.62, 1.5-6 s 0.867/0.65, 2-4 s 0.921/0.49,
                 **3-6 s 0.971/0.37**
threshold        **0.1** and 0.15 0.971/0.37, 0.2 0.955/0.39, 0.25
                 0.908/0.50, 0.3 0.798/0.76
prominence       0 (off) 0.862/0.60, 0.05 0.935/0.42, **0.1 0.971/0.37**,
                 0.15 0.918/0.47
min_segment_s    **1.5** and 2 s alike (0.971/0.37); 1.5 s kept so that
                 activities of 1.5 s can be cut at both ends
onset            off 0.971/0.37, **on 0.971/0.35** (few of these takes pause
                 between activities; on synthetic takes with a pause it puts
                 the cut within 0.1 s of the onset, off leaves it 0.3-1 s
                 early)
short_unmatched  0 (off) 0.971/0.37, **1 0.979/0.35**: it changes one take,
                 86_14, whose 1.6 s activity it finds; with that take left out
                 the others tie and the first option (off) is chosen, so the
                 leave-one-take-out mean does not move (its level and half-width
                 are chosen on cut-down takes, below)
support          0 (off) 0.957/0.41, 0.25 0.971/0.37, **0.5 0.983/0.33**,
                 1 0.948/0.38 (section "Support")
===============  ========================================================

Unless they say otherwise, the figures of the sections after "Support" were measured
before the support test. It changes no cut of the three full-skeleton takes as
recorded, joined or played at another pace, and one of the 60 cases with an activity
cut down (section "Support"), so their figures stand; means over all 11 takes and
four-channel figures there are those of the detector then (leave-one-take-out 0.957 and
0.406 as shipped then).

The prominence is the sensitive setting: on the three full-skeleton takes 0.1 to 0.13
all score F1@1 s 1.0, while 0.07 loses a cut of 13_29 (0.83-0.91) and 0.15 one of 13_30
(0.86); the four-channel takes prefer 0.1 or lower. 0.1 sits at the low edge of the
full-skeleton plateau: on a new take an extra candidate is likelier than a missed one.

Placement (step 5), median |cut - human cut| over matched cuts: 0.09 s on the three
full-skeleton takes, 0.39 s on the four-channel ones. The four angles, not the labels,
are what is missing there: 86_01, read from its full AMC and from its four channels and
scored against the same Krüger windows (cut = first frame after the window's best
estimate, as the labels' README defines it), gets 0.07 s and 0.42 s; the four-channel
errors have both signs (no shift toward a window edge or the next activity's onset
would remove them). Of the matched cuts, 0.83 lie inside the annotators' transition
window on 86_01 from the full skeleton and 0.70 (0.67 leave-one-take-out) on the
four-channel takes (the bench's "in window" column and placement summary). The
steps a-c were chosen earlier on the three full-skeleton takes (split alone 0.24 s,
+turning point 0.09 s, +pause one more cut fixed); not kept then: the turning point
with the best split statistic instead of the nearest, joint velocities in the split
statistic, a linear (mean-pose) cost instead of the kernel (0.54 s: periodic activities
share a mean pose), a context of ``scale_max_s`` and the native frame rate for the
split.

The Krüger windows span the whole passage from one exercise into the next (0.25-2 s)
and their best estimate is its middle (mid at 0.5 of the window on 86_01, 0.14-0.96
elsewhere), while step d puts a cut after a pause at the onset of the next activity,
the window's end. Tried for the four-channel takes, scored on all 11 takes with the
other settings at the shipped values (mean over the eight four-channel takes of the
median error; full-skeleton takes in brackets), none near 0.15 s: each placement step's
own estimate, split 0.34 s (0.24), turning point 0.30 s (0.09), pause 0.37 s (0.09),
onset as shipped 0.39 s (0.09); the middle of the pause the cut lies in instead of its
end, 0.37 s (0.08); the mean of the split and turning point, 0.32 s (0.14), of peak,
split and turning point, 0.31 s (0.13); the middle of the transition segment of a
three-segment kernel fit around the split, 0.39-0.57 s (0.38-0.65); where each frame
near the cut stops looking like the poses 1-4 s before it and starts looking like those
1-4 s after (kernel witness crossing), 0.28-0.30 s (0.24-0.29), and the middle between
the last old-looking and the first new-looking frame, 0.30-0.37 s (0.14-0.39). The
turning point alone would lower the four-channel error but raise the edits per true cut
(0.45 against 0.43 there), the witness crossing would lower both there but triple the
error on the full-skeleton takes, and neither reaches the target, so placement stays as
chosen. Counted in moves (a matched cut outside its window widened to 0.25 s each side),
the witness crossing does not pay either: started from the peak, the split or the placed
cut, with contexts of 0.5-3, 1-3 or 1-4 s, 16-19 moves of the 59 matched four-channel
cuts against 17 as shipped, and 4-6 against 4 on the full-skeleton takes. The split
over the whole neighbouring segments (from the previous kept peak to the next, as a
global kernel change-point fit sees them) instead of at most ``scale_min_s`` and half-way
to a neighbour: four-channel 0.33 s and 0.40 edits per true cut (0.39 s and 0.43 as
shipped), full-skeleton 0.12 s and 0.33 (0.09 s and 0.27), capped at 4-10 s alike or
worse: it trades the takes with a skeleton for those without. A softer pause (step c's
and d's level at 0.6, 0.7, 0.8 or 0.9 of the typical speed instead of half; at 0.7 it
moves 13_29's cut placed 0.8 s early to the shallow slowdown where the annotators cut,
and five others of the full-skeleton takes further from theirs, to 0.2-0.6 s) does the
same: four-channel 0.36, 0.36, 0.34 and 0.35 s (0.38 as shipped), full-skeleton 0.23,
0.17, 0.17 and 0.27 s (0.09), the edits per true cut there 0.33-0.48 (0.27).

How close placement could come with four angles (the bench's placement bound,
``bench_quality.placement_bound_check``, shipped settings, mean over takes of the median
error): an oracle that sees the human cut and picks the best of the detector's five
estimates of each cut (peak and steps a-d) gets 0.183 s on the four-channel takes
(0.069 s with a skeleton), and one that picks the turning point nearest the human cut
among those within 1 s of the placed cut (turning points lie 0.43 s apart there) gets
0.145 s (0.083 s). Without the oracle, a selector learnt to pick that turning point
(a conditional logit over the turning points within 1 s and the placed cut, on their
distances to the peak, the split and the placed cut, the depth of the speed minimum, the
speed before against after, and whether the pose looks like the poses 1-3 s before the
peak or 1-3 s after; trained per kind of take, leave-one-take-out, L2 weight 3-3,000)
gets 0.29-0.38 s on the four-channel takes and leaves the full-skeleton cuts where they
are; trained on both kinds (L2 weight 0.1-10), 0.27-0.34 s, and 0.21-0.32 s on the
full-skeleton takes. Only
an oracle comes near 0.15 s there, so no placement rule of four angles was added.

Support (step 4a)
-----------------
Why. Before the test, the false cuts left out of sample were mostly on the four-channel
takes, six of them at the recorded pace more than 1.5 s from every human cut (86_02 two,
86_10 four), and many more with the takes played slower (``tempo_check``). Each lies
where the windows see one exercise in other proportions: a slower repetition, one side
held longer. MMD compares distributions, so proportions count; whether a pose is taken
on the other side of the peak at all does not depend on them.

The statistic (``cross_support``): for each pose block of the ``SUPPORT_SIDE_S`` (4 s)
after a peak, leaving out ``SUPPORT_GAP_S`` (0.25 s) next to it, gamma (the novelty
kernel's) times the squared distance to the nearest block of the 4 s before it, averaged;
the same the other way; the larger of the two. In kernel units the level needs no
per-take scale. A peak with less than 3 blocks on a side (an end of the take) is kept,
and so is one that step 4c reads as a short activity (``supported_peaks``): an activity
shorter than the sides between two alike ones straddles the peak, each side holds some
of it, and every pose is matched across.

How it was chosen. Its form, the 4 s sides and the gap were set looking at every kept
peak (prominence at least 0.1) of all 11 takes, as recorded and played at 0.8-1.25 times
their pace: with the gap at 0.25 s, the true peaks (within 1 s of a human cut) score at
least 0.53 on the four-channel takes and 1.71 on the full-skeleton ones; 20 of the 30
false four-channel peaks score less than 0.5 (5 of the 6 at the recorded pace); the 6
false full-skeleton peaks (13_29 played slower) 0.68-3.03, beyond its reach (new poses:
the last squat, a cut 1 s off). Sides of 3 s separated less (11 of the 30 below the
lowest true peak), 5 s alike (25), 6 s less (19); gaps of 0.5 and 1 s alike (24 and
25); the smaller of the two sides (both must be new) less. The gap was first 0.5 s; with
one activity of the full-skeleton takes cut down (``real_short_activity_check``,
``unmatched_choice_check``) that lost a true cut in 3 of the 60 cases (13_29's second
activity cut to 1.5, 1.8 and 2.2 s: it lies mostly inside the gap, and the activities
beside it share poses), 0.25 s in one (1.5 s), and the two tie leave-one-take-out, so
0.25 s is shipped. The level is chosen as every setting is, from 0 (off), 0.25, 0.5 and
1 in ``tuning.GRID``: leave-one-take-out 0.971 and 0.367 edits per true cut against
0.957 and 0.406 without the test (table above). Because the sides and the gap were set
on all takes, they were also chosen leave-one-take-out together with the level (sides 3,
4, 5 or 6 s, gaps 0.25, 0.5 or 1 s): 0.962 and 0.388; with each of the 12 pairs fixed
and the level chosen, 0.957-0.977 and 0.349-0.406, none worse than the test off.

What it does. As recorded, 86_02 loses both false cuts (F1@1 s 0.900 -> 1.0) and 86_10
three of its four (0.714 -> 0.909 in-sample; with 86_10 left out, 0.25 ties with 0.5 on
the others and is chosen: 0.769); no true cut is lost, and no cut of the full-skeleton
takes changes (test). Played at 0.8, 0.9, 1, 1.1 and 1.25 times the pace, the
four-channel takes score mean F1@1 s / edits per true cut 0.934/0.44, 0.982/0.29,
0.989/0.30, 0.993/0.24 and 0.964/0.27 against 0.903/0.53, 0.940/0.41, 0.952/0.41,
0.980/0.26 and 0.952/0.29 without it; the full-skeleton takes are unchanged, and of
the short-activity checks only the case above. Of the takes without labels, 02_07
(swordplay) loses one of its four cuts, whose two sides are the same moves. On 40
synthetic takes (``synth``, 60 fps, 200 boundaries) it removes one false cut and loses
one true boundary: idle into walk, two small movements that, in the kernel units of a
take that also holds arm circles and punches, lie 0.34 apart. What it cannot do: two activities that take the same poses in
other proportions or order (a walk and a slow walk, judged by poses alone) lose their
boundary; the pose-distribution novelty sees such a boundary weakly anyway, and on the
full skeleton the level lies far below every true boundary here (1.81 the lowest).

Long takes
----------
The kernel's width (the median heuristic) and so the levels of every peak are the
take's own, so what else a take holds can change its cuts. Joined end to end with the
other takes of their skeleton (``bench_quality.long_take_check``: 13_29 and 13_30, and
13_17, boxing, which has no labels; two at a time in both orders and all three), the
labelled parts score in their own spans mean F1@1 s 0.982 and 0.43 edits per true cut,
against 1.000 and 0.35 alone (cuts within 2 s of a join not scored): with another take
before it, 13_29 gains a false cut 1.3 s before its end, in its last squat (it stands
still for the last 0.8 s), and one cut moves 0.6 s. Tried, not kept: a kernel width per
stretch of the take (the poses scaled so that the median squared distance within ±20 s,
or ±30 s, of each block is the take's). At ±20 s the joined takes score as alone (1.000
and 0.35), and leave-one-take-out over the 11 labelled takes 0.951 and 0.406 (86_03 gains
a cut; as shipped 0.957 and 0.406); at ±30 s 0.991 and 0.39 joined, 0.944 and 0.439
leave-one-take-out; widening only (never sharper than the take's kernel), 1.000 and 0.35,
0.938 and 0.439 at ±20 s, 0.982 and 0.43, 0.951 and 0.416 at ±30 s. None is better out of
sample, and a width from ±20 s would, inside a minute of one activity (walking on), come
from that activity alone and cut its every variation, which no take here can show or
rule out.

Tempo
-----
The time settings (windows, minimum segment, placement reach) are in seconds, chosen on
performers of one pace. Each labelled take played slower and quicker
(``bench_quality.tempo_check``, ``benchdata.played_at``: channels resampled, true cuts
moved with the motion) shows what another pace costs: on the full-skeleton takes mean
F1@1s / edits per true cut 0.889/0.54 at 0.8 times the pace, 0.889/0.61 at 0.9, 1.000/0.27
as recorded, 1.000/0.22 at 1.1 and 0.889/0.38 at 1.25 (four-channel 0.903/0.53,
0.940/0.41, 0.952/0.41, 0.980/0.26, 0.952/0.29). Played 10 % slower, 13_29 gets seven cuts
for five (one inside its arm circles, one in its last squat, and one that lands 1.03 s
from its boundary): the windows then span fewer cycles of each activity, and the phases
inside an activity show. Tried, not kept: the ``tempo`` setting, which scales the time
settings by the take's own movement cycle (``movement_period``: over poses, the median lag
at which a pose first comes back, 1.0-1.7 s on these takes) over ``TEMPO_REFERENCE_S``
(1.3 s, the median of the ten captures; leaving one out moves it by at most 0.04 s). It
holds the slower takes (full-skeleton 0.933/0.34 at 0.8 and 0.933/0.28 at 0.9), but the
cycle a take shows depends on which activities it holds as much as on the performer's
pace: 13_30, slow exercises of 4-5 s, gets windows a fifth longer and loses two of its
four cuts as recorded (full-skeleton 0.889/0.30 at 1.0). Leave-one-take-out with tempo
imposed, mean F1@1 s 0.925 and 0.406 edits per true cut (shipped 0.957 and 0.406; with
1.33 s as the reference 0.925 and 0.439), and the full-skeleton takes as recorded
0.952/0.30 with 1.33 s: the setting hangs on a constant the takes cannot pin down, and
loses cuts at the pace the settings were chosen for.

With the support test (step 4a) in the grid, tempo imposed scores leave-one-take-out
0.973 and 0.336 edits per true cut, the folds choosing prominence 0.05, a minimum
segment of 2 s and the unmatched-poses step off (the bench's ``tried/loo`` row; shipped
0.971 and 0.367; with the support test's gap at 0.5 s, 0.992 and 0.269). Still not
shipped: it is a knife edge where the shipped settings sit on plateaus (with tempo on,
prominence 0.1 scores 0.885 and 0 0.952, a minimum segment of 1.5 s 0.929, the
unmatched-poses step on 0.922); it gives up short activities (an inner activity of the
full-skeleton takes cut down to 1.8 s found at both ends in 2 of 12 cases against 5,
2.5 s 4 against 9, false cuts 8 against 3, and its 2 s minimum segment, scaled by the
cycle, cannot cut a 1.5 s activity at both ends); and it holds another pace no better
on the full-skeleton takes (0.889/0.54, 0.889/0.48, 1.000/0.22, 0.970/0.37 and 0.944/0.43
at 0.8-1.25 times the pace, shipped 0.889/0.54, 0.889/0.61, 1.000/0.27, 1.000/0.22 and
0.889/0.38). Its gain is on the takes as recorded, which the grid was chosen on.

Short activities: unmatched poses (step 4c)
-------------------------------------------
Windows of 3-6 s see an activity shorter than about 3 s between two longer ones as one
broad peak, and one of its two boundaries is lost. What a short activity has that the
inside of a long one lacks: a long activity repeats, so each of its poses has a look-
alike a cycle or two away (1.5-8 s), while inside an activity shorter than twice
``min_segment_s`` every pose that far away belongs to the neighbours. ``unmatched_poses``
measures, per 10 Hz block, gamma (the novelty kernel's) times the squared distance to
the most similar block ``min_segment_s`` to 8 s away; ``unmatched_sides`` looks, within
1.5 s of each kept peak, for the 1.2 s stretch with the highest mean, and at
``short_unmatched`` or more replaces the peak by two, 1.25 s either side of the
stretch's middle, unless kept peaks already lie on both sides of it within
``scale_min_s``. In kernel units the level needs no per-take scale: 1 means that, on
average, no pose around looks as alike as e^-1 by the kernel that finds the peaks. The
stretch must also reach ``UNMATCHED_RELATIVE`` (2.3) times the median over the take: the
step rests on a take that repeats itself, and in one that does not (boxing, dance, a
fight) every pose is somewhat unmatched and a stretch at the level says nothing.

How it was chosen. The 8 s context, the 1.2 s stretch and the 1.5 s reach (half the
shortest window) were set before scoring; the level and the half-width were chosen from
0.5, 1, 1.5, 2, 3 (or off) and 0.75, 1, 1.25 s leave-one-take-out on cut-down takes
(``bench_quality.unmatched_choice_check``, in the bench output): each full-skeleton
take left out in turn, the setting chosen on the other takes as they are (four-channel
ones included), with one inner activity cut down to 1.5-3 s and with all cut down to
2.5-5 s, and scored on the take left out. Every fold chose level 1 (half-width 1.25 s
twice, 1 s once); over the three takes left out, both boundaries of the one short
activity were found in 37 of 60 cases against 8 with the step off, mean F1@1 s 0.948
against 0.869 with one activity cut down and 0.892 against 0.789 with all cut down, the
takes as they are unchanged (1.0). Chosen on all: level 1, 1.25 s, shipped. The rule
about kept peaks on both sides was added after seeing takes cut down to 4 s throughout,
where slow exercises that do not repeat within 4 s looked unmatched (mean F1@1 s 0.674
without it, 0.903 with it, 0.896 with the step off). The other constants barely matter
there: a context of 6 or 12 s and a stretch of 1.5 s score the same on the takes as they
are and cut down (1.5 s: 0.970 instead of 0.903 at 4 s throughout); a stretch of 0.8 s
or a reach of 1 s lose 0.06 at 4 s throughout; a reach of 2 s reaches into the
neighbours (8-11 false cuts in the 12 cases of each length, mean F1@1 s 0.929 over the
11 takes).

What it does, beside the step off (``python -m motionlib bench --loo``): on the 11
takes as they are it changes 86_14 alone, whose 1.6 s activity it finds (F1@1 s 0.91 ->
1.0; mean 0.957 -> 0.965, edits per true cut 0.386 -> 0.370); with one inner activity of
the full-skeleton takes cut down to 1.8 s or 2.5 s both of its boundaries are found in
5 and 9 of 12 cases instead of 0 and 2 (false cuts 3 and 3 against 3 and 4); with every
inner activity cut down to 2.5, 3, 3.5 and 4 s mean F1@1 s 0.896, 0.915, 0.886 and
0.903 instead of 0.579, 0.743, 0.849 and 0.896, at 4.5 and 5 s 0.939 and 0.914 instead
of 0.970 and 0.939 (there a slow exercise cut down to its first and last seconds can
still look unmatched); on the synthetic takes with 1.5-6 s activities 27 of the 35
boundaries beside an activity under 2.5 s instead of 21. The four-channel takes other
than 86_14 get no cut from it; in their four angles the passage between two exercises is
as unmatched as a short activity in the poses of a full skeleton, so a level relative to
the take's own median (tried first: 4-8 times) fired at almost every peak there (mean
F1@1 s 0.84-0.94 over the 11 takes). Also tried, not kept: moving to the top of the
hill of the best stretch in reach (so that two peaks beside one stretch agree on its
middle), which walks into unmatched moments inside the neighbours (mean F1@1 s 0.935).

The take-median guard was added after the level and half-width were chosen, when the
bench's takes without segment labels (``bench_quality.unmatched_guard_check``) showed
the step splitting a peak of CMU 13_17, boxing throughout, whose poses have a median
level of 0.62 and the stretch 1.03 (1.7 times). No label says whether that split is
wrong, so the factor is not chosen by a score: 2.3 is the geometric middle between that
1.7 and the lowest ratio of any firing on the labelled material and the takes cut down
from it (3.2, a true one, in 13_30 with every activity cut down to 2.5 s: a take made of
short activities is itself less repetitive, so its median is higher; the median ratio
of the 45 firings there is 12.4, 86_14's four-channel stretch 173), and it changes no
cut there: every table of ``python -m motionlib bench --loo`` is the same with and
without it. Of the other takes without labels, 02_07 (swordplay) keeps its firing (4.7
times, at 15-17 s, where a foot swings high and the hips dip as nowhere else in the
take); the two 4-6 s clips have none.

Short activities: tried before step 4c, not shipped
---------------------------------------------------
The figures of this section were measured without step 4c (``short_unmatched`` 0); at
the ends of a take (its last paragraph) step 4c changes nothing.

Windows of 3-6 s see an activity shorter than about 2.5 s between two long ones as one
broad peak, so one of its two boundaries is often lost: on synthetic takes with 1.5-6 s
activities (``bench_quality.short_activity_check``) 21 of the 35 boundaries beside an
activity shorter than 2.5 s are found within 1 s (0.60), and on synthetic takes of 6 s,
1.8 s and 6 s activities (30 seeds and action triples) both boundaries of the short one
in 20 %. Shorter windows find them (0.93 with 1.5-6 s windows) but cut inside real
activities (table above). Step 4b keeps the 3-6 s windows for deciding where the big
boundaries are and asks windows of ``min_segment_s`` only about the far side of a
kept peak: a shoulder of it (a local maximum without the prominence, at most
``scale_min_s`` away) becomes a cut when the short-window novelty has a peak within
0.5 s of both the shoulder and the kept peak, each ``short_activity`` times as prominent
as the take's median short-window peak inside its activities. On the synthetic takes
``short_activity`` 4 finds 26/35 (0.74) and both sides of the 1.8 s activity in 77 %;
8 finds 25/35 (0.71) and 70 %.

On the real takes it does not pay. With ``short_activity`` options 0 (off), 4 and 8
and ``short_uniformity`` options 0 (no test), 0.2 and 0.3 added to the grid
(``tuning.TRIED``), the choice made without the take scored gets mean F1@1 s 0.947 and
0.43 edits per true cut (row ``tried/loo``), against 0.957 and 0.41 without them
(``default/loo``). On the other takes, min_segment_s 2 s with ``short_activity`` 8 and
no uniformity test scores best (it finds the one short real activity, 86_14's 1.6 s,
four channels); on the take left out it adds a false cut to 86_03 and 86_08, and with
86_14 itself left out it is not chosen: one real short activity among 11 takes cannot
carry the choice. With one option imposed, the others still chosen without the take:
``short_activity`` off 0.957/0.41, 4 0.910/0.48, 8 0.947/0.43; ``short_uniformity`` 0
0.947/0.43, 0.2 and 0.3 0.957/0.41 (with the test imposed, ``short_activity`` off is
chosen for every take: the test makes the step harmless, not useful, here). The three
full-skeleton takes get no extra cut at 4 or 8; on the four-channel takes almost every
added cut is false. What the short windows see there is the transition itself:
annotators' windows are 0.4-1.25 s wide, and the performer leaving one exercise and
settling into the next looks to a 1.5-2 s window just like a short activity, so most
false cuts lie 1.5-2.5 s from a true one, on the other side of its transition. The
uniformity test (``mixing``: an activity repeats, so its two halves look alike; a
passage from one activity into the next morphs) removes most of them: scored on all 11
takes with the other settings at the shipped values, ``short_activity`` 4 gets 0.886
and 0.54 edits without it, 0.948/0.41 with 0.2 and 0.941/0.41 with 0.3 (8: 0.948 and
0.945); the cuts left are on 86_02, a 1.6 s stretch that looks like one activity and
that the annotators cut in the middle, and 86_08. It also loses short activities: on
the synthetic check 23/35 and 25/35 at 4 (22 and 24 at 8), both sides of the 1.8 s
activity in 60 % and 63 % (53 % and 57 % at 8). Other designs, each scored on all 11
takes with the other settings at the shipped values (every option of theirs that found
more short-activity boundaries lowered the mean F1@1 s there, 0.957 off, so none was a
choice to make leave-one-take-out):

- a pair of prominent 1.5 s-window peaks around a kept peak with the long-window novelty
  between them at least 0.3-0.8 of the peak (a plateau): mean F1@1 s 0.78-0.95, synthetic
  21-28/35;
- a three-segment kernel fit around each kept peak (the extra split kept when it
  lowers the kernel cost by 0.2-1 times the first split's gain): 0.69-0.95, synthetic at
  most 24/35 (real transitions fit three segments as well as short activities do);
- shoulders confirmed by short-window peaks of a fixed prominence (0.1-0.6 MMD²):
  0.82-0.95;
- as step 4b with the level a quantile of the take's short-window peaks (0.75, 0.9,
  the largest) instead of a multiple of the median: 0.82-0.957 (no cut added at the
  largest), synthetic 21-26/35;
- strong short-window peaks within ``scale_min_s`` of a kept peak, no shoulder needed
  (4-8 x the median): synthetic 27-30/35 but 0.84-0.90;
- step 4b with the uniformity test and a pause test (a short stretch moving at less
  than half its neighbours' speed is a pause, not an activity): no change (86_02's
  stretch is not a pause in its four angles).

So the zero-shot detector keeps ``short_activity`` off; a studio whose takes hold such
activities can get them from its own examples (``motionlib.adapt`` switches to shorter
windows: 0.91 on the synthetic check) or set ``short_activity`` 4 with
``short_uniformity`` 0.3.

Real short activities are harder than synthetic ones, and none of this finds them well.
With each inner activity of the three full-skeleton takes cut down by removing its
middle (``benchdata.shortened``: real entry and exit, 12 cases;
``bench_quality.real_short_activity_check``, in the bench output), both boundaries of a
1.8 s activity are found within 1 s in 0 of 12 cases zero-shot (one of them in 11 of 24),
with ``short_activity`` 4 and ``short_uniformity`` 0.3 also 0 (on real poses windows of
1.5 s fire inside activities almost as strongly as at boundaries, so 4 times their
median prominence is out of reach), with windows of 2-4 s 5 of 12 at 10 false cuts
against 3, and adapted to the other takes as they are and shortened 0 of 12 (it keeps
the 3-6 s windows); at 2.5 s 2, 3, 7 and 5 of 12 (false cuts 4, 4, 11, 12). Tried there,
not kept: a long-window peak next to a kept one (within ``scale_min_s``, without the
prominence) cut when the stretch between the two differs from the ``scale_min_s``
before and after it (MMD² at least 0.4 against both): 6 of 12 at 1.8 s, but false cuts
on 13_29 and on two four-channel takes as they are (mean F1@1 s 0.957 -> 0.936 over the
11 takes, levels 0.3-0.6 alike or worse); two short-window peaks 1-3 s apart on either
side of a kept peak replacing it (no shoulder needed; windows of 1.5 or 2 s, each peak
2-6 times the median short-window peak inside activities): at 1.8 s 0-7 of 12, but mean
F1@1 s 0.74-0.88 over the 11 takes as they are (the passage between two exercises shows
the same pair); a kept peak wider than the others (its width at half prominence): the
peak that holds a 1.8 s activity is 1.8-4.9 s wide, the kept peaks of the takes as
they are 0.7-4.7 s, so the long windows do not see a short activity as a wider peak; the
stretch between a kept peak and a peak of 1 or 1.5 s windows 1-3.5 s from it, judged by
its MMD² to the 1.5 s before and after it, to its own other half, and how much its poses
recur at lags of 0.5 s and more: over the 11 takes as they are and the 12 cases at 1.8
s, 62 of the 1,473 such candidates are a true boundary, and of the 20 that each of these
(and their ratios) ranks highest at most 3 are (area under the ROC curve 0.66-0.87);
windows of one local period (the lag of 0.5-2.5 s at which the poses of the 2.5 s
before, or after, look most like themselves again), so that inside a periodic activity a
window always holds one whole cycle: on the full-skeleton takes the peaks inside
activities stay as high (median 0.52 MMD², 95th percentile 1.20) against 0.74 at the
boundaries (fixed 1.5 s windows: 0.32, 0.86 and 0.57), two periods 0.35, 1.14 and 0.63.
Asymmetric windows, 3 s on one side and 1 s on the other (the long side holds the
neighbouring activity's whole distribution, the short one only the short activity), do no
better: over the three full-skeleton takes their peaks inside activities have median 0.44
MMD², 90th percentile 0.75, and at the 13 boundaries of 1.8 s activities that the
detector misses they reach 0.40-0.80. Real activities change inside at the 1-2 s scale
(sides alternate, a repetition pauses) as much as at their ends: the novelty of
short windows cannot tell the two apart. Whether a pose recurs can (step 4c above): a
short activity's middle is unlike everything around it, the inside of a long activity
is not.

Takes made of short activities throughout are where fixed 3-6 s windows cost most: with
every inner activity of the three full-skeleton takes cut down the same way, mean F1@1 s
0.58 at 2.5 s, 0.74 at 3 s and 0.90 at 4 s, where windows of 2-4 s get 0.69, 0.90 and
0.97 (on the takes as they are 2-4 s windows score 0.898, table above). Tried, not kept:
choosing the windows per take, 2-4 s when the cuts they add each lower the
within-segment kernel cost (mean over the take's novelty blocks) by more than a level.
13_29 as it is, which must keep 3-6 s, gains 0.017 per added cut; the shortened 86_01
and 13_29 at 3 s, which need 2-4 s, gain 0.020 and 0.027; 13_29 with only its first
activity cut to 2.5 s gains 0.019 and loses F1 with 2-4 s (0.89 -> 0.50). No level
separates them with any margin, and on the four-channel takes the gains are another
scale (0.001-0.012), so the windows stay fixed.

At the start or end of a take a short activity has one boundary, and that one is found:
with the first or last activity of the three full-skeleton takes cut down by dropping the
take's first or last frames (``benchdata.trimmed``,
``bench_quality.edge_activity_check``), within 1 s in 5 of 6 cases at 1.5 s, 4 of 5 at
1.8 s and 5 of 5 at 2.5 s. The miss is 86_01's last activity at 1.5-1.8 s: windows
longer than twice the activity see the one before it again in the mirror beyond the
take's end, and the novelty peak lies 1.5 s inside the take. Letting the split reach
from such a peak to the take's end (peaks within 3-6 s of an end) found no more of them and
lowered the mean F1@1 s over the 11 takes to 0.934; averaging, near an end, only the
windows that see at most one reflection of real poses found all of them (6/6, 5/5, 5/5)
but with 4 false cuts at each length, and 0.905 over the 11 takes (shorter windows fire
inside activities).

All durations are in seconds, so the same defaults work at any frame rate.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field, replace

import numpy as np
from scipy.signal import find_peaks
from scipy.spatial.distance import cdist

from motionlib import features
from motionlib.kinematics import body_frame_rows
from motionlib.segmenters.base import (
    Param,
    ParamError,
    Segmentation,
    Segmenter,
    first_frame,
    full_length,
    take_positions,
)
from motionlib.skeleton import canonical_indices

POSE_JOINTS = (
    "head", "chest", "left_elbow", "right_elbow", "left_wrist", "right_wrist",
    "left_knee", "right_knee", "left_ankle", "right_ankle",
)


def pose_features(
    positions: np.ndarray, joints: dict[str, int], *, fps: float, velocity_s: float
) -> np.ndarray:
    """Heading-invariant pose vectors.

    Returns
    -------
    (n_frames, n_features): body-frame positions of ``POSE_JOINTS``, root height
    (minus its median) and, when ``velocity_s > 0``, their velocities times
    ``velocity_s`` seconds (a length, so both parts share one unit).
    """
    body = features.body_frame_positions(positions, joints, [joints[j] for j in POSE_JOINTS])
    pose = body.reshape(len(positions), -1)
    height = positions[:, joints["root"], 1:2]
    x = np.concatenate([pose, height - np.median(height)], axis=1)
    return _with_velocities(x, fps=fps, velocity_s=velocity_s)


def _with_velocities(x: np.ndarray, *, fps: float, velocity_s: float) -> np.ndarray:
    if velocity_s > 0:
        smooth = features.lowpass(x, fps=fps, cutoff_hz=min(3.0, 0.45 * fps))
        x = np.concatenate([x, np.gradient(smooth, axis=0) * fps * velocity_s], axis=1)
    return x


def take_features(take, *, velocity_s: float = 0.0) -> tuple[np.ndarray, int]:
    """The detector's per-frame feature vectors of a take.

    A take with a skeleton gives ``pose_features``; a take known only by a few angle
    channels (``benchdata.ChannelTake``, no ``skeleton``) gives those angles in radians:
    the kernel's width follows the data (median heuristic), so any unit works.

    Returns
    -------
    x : (n_used, n_features); first : take frame of ``x[0]`` (after a rest pose).
    """
    if getattr(take, "skeleton", None) is None:
        return np.radians(np.asarray(take.channels, dtype=float)), 0
    if getattr(take, "positions", None) is not None:  # computed already: used as they are
        positions, joints, first = take_positions(take)
        return pose_features(positions, joints, fps=float(take.fps), velocity_s=velocity_s), first
    # Else the same features straight from the channels, without every joint's positions.
    joints, first = canonical_indices(take), first_frame(take)
    x = body_frame_rows(take, [joints[j] for j in POSE_JOINTS], root=joints["root"],
                        left_hip=joints["left_hip"], right_hip=joints["right_hip"], first=first)
    x[:, -1] -= np.median(x[:, -1])
    return _with_velocities(x, fps=float(take.fps), velocity_s=velocity_s), first


# Tempo: the movement cycle (s) the time settings are chosen for, how far a take's own
# cycle may scale them, the lags (s) a pose's look-alike is sought at and the pose rate
# (Hz) it is sought on, and how many poses are sampled for it at most.
TEMPO_REFERENCE_S = 1.3
TEMPO_SCALE = (0.5, 2.0)
TEMPO_LAGS_S = (0.3, 6.0)
TEMPO_RATE_HZ = 30.0
TEMPO_SAMPLES = 3000
TIME_SETTINGS = ("scale_min_s", "scale_max_s", "min_segment_s", "refine_s")


def movement_period(x: np.ndarray, fps: float) -> float | None:
    """The take's typical movement cycle (s): over poses, the median lag at which a pose
    first comes back, i.e. the first local minimum of its squared distance to the poses
    ``TEMPO_LAGS_S`` later that falls below half the largest distance before it (the
    body has moved away and returned). A performer moving 10 % slower has a 10 % longer
    cycle. None when fewer than a tenth of the sampled poses come back (a take too short
    or without repetition)."""
    step = max(1, int(round(fps / TEMPO_RATE_HZ)))
    blocks = block_mean(x, step)
    rate = fps / step
    lags = np.arange(max(1, int(round(TEMPO_LAGS_S[0] * rate))),
                     int(round(TEMPO_LAGS_S[1] * rate)) + 1)
    n = len(blocks) - lags[-1]
    if n < 10:
        return None
    rows = np.arange(0, n, max(1, n // TEMPO_SAMPLES))
    d = np.empty((len(rows), len(lags)))
    for j, lag in enumerate(lags):
        diff = blocks[rows + lag] - blocks[rows]
        d[:, j] = np.einsum("ij,ij->i", diff, diff)
    low = np.zeros_like(d, dtype=bool)
    low[:, 1:-1] = (d[:, 1:-1] <= d[:, :-2]) & (d[:, 1:-1] <= d[:, 2:])
    back = low & (d < 0.5 * np.maximum.accumulate(d, axis=1))
    found = back.any(axis=1)
    if found.sum() < max(1, len(rows) // 10):
        return None
    return float(np.median(lags[np.argmax(back[found], axis=1)]) / rate)


def tempo_scale(x: np.ndarray, fps: float) -> float:
    """How much slower than ``TEMPO_REFERENCE_S`` the take moves (``movement_period``),
    within ``TEMPO_SCALE``; 1 when its cycle cannot be told."""
    period = movement_period(x, fps)
    if period is None:
        return 1.0
    return float(np.clip(period / TEMPO_REFERENCE_S, *TEMPO_SCALE))


def scaled_times(p: dict, scale: float) -> dict:
    """``p`` with ``TIME_SETTINGS`` times ``scale``, kept within their bounds."""
    if scale == 1.0:
        return p
    out = dict(p)
    for key in TIME_SETTINGS:
        param = Default.params[key]
        out[key] = float(np.clip(p[key] * scale, param.min, param.max))
    if out["rate_hz"] * out["scale_max_s"] > MAX_WINDOW_SAMPLES:
        out["scale_max_s"] = MAX_WINDOW_SAMPLES / out["rate_hz"]
        out["scale_min_s"] = min(out["scale_min_s"], out["scale_max_s"])
    return out


def block_mean(x: np.ndarray, step: int) -> np.ndarray:
    """Average consecutive blocks of ``step`` frames: (n, d) -> (n // step, d)."""
    n = len(x) // step
    return x[: n * step].reshape(n, step, -1).mean(axis=1)


def median_sq_distance(x: np.ndarray, max_points: int = 1000) -> float:
    """Median squared distance between rows (on an even subsample for long inputs)."""
    sub = x[:: max(1, len(x) // max_points)]
    sq = (sub * sub).sum(axis=1)
    d2 = sq[:, None] + sq[None, :] - 2 * sub @ sub.T
    # The pairs above the diagonal, row by row: the order np.triu_indices gives, without
    # its two index arrays of n² / 2 entries each.
    return float(np.median(np.concatenate([row[i + 1:] for i, row in enumerate(d2)])))


def mmd_novelty(x: np.ndarray, w: int, gamma: float) -> np.ndarray:
    """MMD² between the ``w`` samples before and the ``w`` samples from each instant.

    Only kernel values at lags below ``2 w`` are needed, so memory and time are
    O(n w) rather than O(n²), which keeps hour-long takes cheap.

    Parameters
    ----------
    x : (n, d) samples; w : window length in samples; gamma : kernel 1 / bandwidth².

    Returns
    -------
    (n,) biased MMD² estimate at each split t (0 where a window would leave the take).
    """
    return multi_mmd_novelty(x, [w], gamma)[0]


def multi_mmd_novelty(x: np.ndarray, widths, gamma: float) -> list[np.ndarray]:
    """``mmd_novelty`` for several window lengths, sharing the kernel at each lag.

    Returns
    -------
    list of (n,) arrays, one per width in ``widths``.
    """
    n = len(x)
    acc = {}
    for w in widths:
        if w >= 1 and n >= 2 * w:
            t = np.arange(w, n - w + 1)
            acc[w] = (t, np.zeros(len(t)), np.zeros(len(t)))
    n_lags = 2 * max(acc, default=0)
    group = max(1, min(LAG_GROUP, LAG_ELEMENTS // max(n, 1)))
    for first in range(0, n_lags, group):
        lags = range(first, min(n_lags, first + group))
        # sums[i, j]: the kernel at lag lags[j] summed over the pairs starting before i
        sums = np.zeros((n + 1, len(lags)))
        np.cumsum(lag_kernel(x, lags, gamma), axis=0, out=sums[1:])
        for lag, c in zip(lags, sums.T, strict=True):
            _add_lag(acc, lag, np.ascontiguousarray(c))
    out = []
    for w in widths:
        curve = np.zeros(n)
        if w in acc:
            t, within, cross = acc[w]
            curve[t] = np.maximum((within - 2 * cross) / (w * w), 0.0)
        out.append(curve)
    return out


# Lags whose kernels are computed together: LAG_GROUP, fewer on long inputs so that each
# of the few (n, lags) arrays holds at most LAG_ELEMENTS values (8 MB: an hour-long take
# needs no more memory than a short one); and the most rows per matrix product (each
# row's product also covers lags - 1 columns it does not need, so short blocks waste
# less), fewer when the product would exceed SMALL_PRODUCT.
LAG_GROUP = 64
LAG_ELEMENTS = 2**20
LAG_ROWS = 64
# Matrix products of m x n x k at most this size: OpenBLAS computes them on one thread and
# splits larger ones over threads. On a 2-core machine with the other core busy, a split
# product took 2x (64 x 191 x 31) to 40x (180 x 180 x 31) as long as on one thread.
SMALL_PRODUCT = 4 * 65536


def _small_rows(rows: int, cols: int, d: int) -> int:
    """At most ``rows``, and few enough that rows x cols x d stays within SMALL_PRODUCT."""
    return max(1, min(rows, SMALL_PRODUCT // max(1, cols * d)))


def lag_kernel(x: np.ndarray, lags: range, gamma: float) -> np.ndarray:
    """The Gaussian kernel between each sample and the one ``lag`` later, for each lag.

    ``|a - b|² = |a|² + |b|² - 2 a.b`` with the dot products from matrix products over
    short blocks of rows: the products of a band of the Gram matrix, several times fewer
    passes over memory than differencing the samples lag by lag.

    Returns
    -------
    (n, len(lags)): ``exp(-gamma |x[i + lag] - x[i]|²)``, 0 where ``i + lag`` is past the
    end; exactly 1 at lag 0.
    """
    n, m, first = len(x), len(lags), lags[0]
    sq = np.einsum("ij,ij->i", x, x)
    dots = np.empty((n, m))
    rows = LAG_ROWS
    while rows > 1 and rows * (rows + m - 1) * x.shape[1] > SMALL_PRODUCT:
        rows //= 2
    for a in range(0, n, rows):
        b = min(n, a + rows)
        block = np.zeros((b - a, b - a + m - 1))
        later = x[a + first : b + first + m - 1]
        block[:, : len(later)] = x[a:b] @ later.T
        # row r of the band starts at block[r, r]: one step further along each row
        dots[a:b] = np.lib.stride_tricks.as_strided(
            block, shape=(b - a, m), strides=(block.strides[0] + block.strides[1],
                                              block.strides[1]))
    padded = np.concatenate([sq, np.zeros(first + m)])
    sq_later = np.lib.stride_tricks.sliding_window_view(padded[first:], m)[:n]
    k = np.exp(-gamma * np.maximum(sq[:, None] + sq_later - 2 * dots, 0.0))
    for j, lag in enumerate(lags):
        k[max(0, n - lag):, j] = 0.0
    if first == 0:
        k[:, 0] = 1.0
    return k


def _add_lag(acc: dict, lag: int, c: np.ndarray) -> None:
    """Add the pairs at ``lag`` to each width's within- and cross-window kernel sums;
    ``c[i]`` sums their kernel over the pairs starting before ``i``."""
    for w, (t, within, cross) in acc.items():
        if lag >= 2 * w:
            continue

        def at(offset, w=w, t=t):  # c[t + offset] for every split t (a slice, not a gather)
            return c[t[0] + offset : t[0] + offset + len(t)]

        if lag < w:  # pairs (i, i + lag) inside the past and inside the future window
            mult = 1.0 if lag == 0 else 2.0
            within += mult * (at(-lag) - at(-w) + at(w - lag) - at(0))
        # pairs with i in the past window and i + lag in the future one: i from
        # max(t - w, t - lag) up to min(t, t + w - lag)
        if 1 <= lag <= w:
            cross += at(0) - at(-lag)
        elif lag > w:
            cross += at(w - lag) - at(-w)


def mirrored_novelty(x: np.ndarray, w: int, gamma: float) -> np.ndarray:
    """``mmd_novelty`` with the take mirrored at both ends.

    Mirroring lets a window that would run off the take see the nearest real poses
    again, so an activity shorter than a window at the very start or end still
    produces a peak at its boundary.
    """
    return mirrored_novelties(x, [w], gamma)[0]


def mirrored_novelties(x: np.ndarray, widths, gamma: float) -> list[np.ndarray]:
    """``mirrored_novelty`` for several widths at once (one mirror, shared kernels)."""
    widths = [min(w, len(x) - 1) for w in widths]
    pad = max(widths, default=0)
    if pad < 1:
        return [np.zeros(len(x)) for _ in widths]
    padded = np.concatenate([x[pad:0:-1], x, x[-2 : -pad - 2 : -1]])
    curves = multi_mmd_novelty(padded, widths, gamma)
    return [c[pad : pad + len(x)] if w >= 1 else np.zeros(len(x))
            for c, w in zip(curves, widths, strict=True)]


# A pause is a slowest frame at most this fraction of the typical speed around it.
PAUSE_RATIO = 0.5


def settle_frame(speed: np.ndarray, cut: int, radius: int, context: int) -> int:
    """Move ``cut`` to a pause within ``radius`` frames, if there is one.

    Performers often stop briefly between two activities and annotators cut there. The
    slowest frame near the cut counts as such a pause only when it is well below the
    median speed over ``±context`` frames: every periodic movement slows down at its
    turning points, and those must not pull a cut away from the statistical change.
    """
    a, b = max(1, cut - radius), min(len(speed) - 1, cut + radius + 1)
    if b <= a:
        return cut
    slowest = a + int(np.argmin(speed[a:b]))
    typical = np.median(speed[max(0, cut - context) : cut + context])
    return slowest if speed[slowest] < PAUSE_RATIO * typical else cut


# How far (s) the onset of the next activity may lie after a pause.
ONSET_MAX_S = 3.0


def onset_frame(speed: np.ndarray, cut: int, stop: int, context: int) -> int:
    """The end of the pause ``cut`` lies in: where the next activity sets off.

    When the speed at ``cut`` is below ``PAUSE_RATIO`` of the median speed over
    ``±context`` frames, the performer may be standing between two activities, and
    annotators who cut at the onset of the next one cut where the speed rises past that
    level again. Only a pause that ends by frame ``stop``, lasts at most ``stop - cut``
    frames in all and is followed by ``context`` frames at the typical speed (and at
    least half the speed of the ``context`` frames before) counts: a
    longer slow stretch, or one followed by slow motion, is an activity of its own
    (standing, idling), not a pause between two. Elsewhere ``cut`` is returned unchanged.
    """
    level = PAUSE_RATIO * np.median(speed[max(0, cut - context) : cut + context])
    if not speed[cut] < level or stop <= cut:
        return cut
    above = np.flatnonzero(speed[cut : stop + 1] >= level)
    if not len(above):
        return cut
    end = cut + int(above[0])
    before = np.flatnonzero(speed[max(0, end - (stop - cut)) : cut] >= level)
    # The next activity must then move at least at the typical speed and at half the
    # previous one's: a slow one (idling, swaying) is not set off by a rise of a moment.
    after = np.median(speed[end : end + context])
    moving = after >= max(level / PAUSE_RATIO,
                          PAUSE_RATIO * np.median(speed[max(0, cut - context) : cut]))
    return end if len(before) and moving else cut


def split_gains(x: np.ndarray, gamma: float) -> np.ndarray:
    """How well each split cuts ``x`` into two homogeneous segments.

    With the Gaussian kernel k, the within-segment variance of a split at t in the
    kernel's feature space is ``n - S(0, t) / t - S(t, n) / (n - t)``, where S(a, b) sums
    k over all pairs in ``x[a:b]`` (the kernel change-point cost). Its constant part
    dropped, the best split has the largest gain ``S(0, t) / t + S(t, n) / (n - t)``.

    Parameters
    ----------
    x : (n, d) samples; gamma : kernel 1 / bandwidth².

    Returns
    -------
    (n - 1,) gains of the splits t = 1 .. n - 1 (empty when n < 2).
    """
    n = len(x)
    k = np.exp(-gamma * sq_distances(x))
    # With c[a, b] the sum of k[:a, :b] and k symmetric: c[t, n] sums the first t rows,
    # and c[t, t] adds, row by row, the diagonal entry and twice the entries left of it.
    rows = np.cumsum(k.sum(axis=1))  # c[t, n] for t = 1 .. n
    square = np.cumsum(2 * np.tril(k, -1).sum(axis=1) + k.diagonal())  # c[t, t]
    t = np.arange(1, n)
    inside, before = square[:-1], rows[:-1]
    right = square[-1] - 2 * before + inside
    return inside / t + right / (n - t)


def sq_distances(x: np.ndarray) -> np.ndarray:
    """(n, n) squared distances between the rows of ``x``: ``|a|² + |b|² - 2 a.b`` (at
    least 0) with the dot products from matrix products of a few rows each, small enough
    (SMALL_PRODUCT) to run on one thread. Three times faster than ``cdist`` here."""
    n, d = x.shape
    sq = np.einsum("ij,ij->i", x, x)
    gram = np.empty((n, n))
    rows = _small_rows(n, n, d)
    for a in range(0, n, rows):
        gram[a : a + rows] = x[a : a + rows] @ x.T
    return np.maximum(sq[:, None] + sq[None, :] - 2 * gram, 0.0)


def best_split(x: np.ndarray, cut: int, lo: int, hi: int, *, step: int, radius: int,
               gamma: float) -> int:
    """The frame within ``radius`` of ``cut`` that best splits ``x[lo:hi]`` in two.

    ``x`` is averaged into blocks of ``step`` frames first, so the split is found to
    within one block; ``cut`` itself is returned when no block boundary is in reach.
    """
    if hi - lo < 2 * step:  # not two blocks: nothing to split
        return cut
    blocks = block_mean(x[lo:hi], step)
    frames = lo + step * np.arange(1, len(blocks))
    near = np.abs(frames - cut) <= radius
    if not near.any():
        return cut
    gains = split_gains(blocks, gamma)
    return int(frames[near][np.argmax(gains[near])])


def fine_speed(x: np.ndarray, *, fps: float) -> np.ndarray:
    """Pose speed per frame with the poses low-passed at 3 Hz first, as for the
    velocities, so that capture jitter makes no turning points or onsets of its own."""
    smooth = features.lowpass(x, fps=fps, cutoff_hz=min(3.0, 0.45 * fps))
    return features.frame_speed(smooth, fps=fps)


def turning_points(x: np.ndarray, *, fps: float) -> np.ndarray:
    """Frames where the pose momentarily slows down (local minima of ``fine_speed``).

    Returns
    -------
    (n_points,) int frames, increasing.
    """
    return speed_minima(fine_speed(x, fps=fps))


def speed_minima(speed: np.ndarray) -> np.ndarray:
    """The frames of the local minima of ``speed``: the turning points when it is
    ``fine_speed`` (already computed, as ``pose_speeds`` gives it)."""
    frames, is_max = features.local_extrema(speed)
    return frames[~is_max]


def nearest(points: np.ndarray, target: int, radius: int) -> int:
    """The point nearest ``target`` if one is within ``radius``, else ``target``."""
    if len(points) == 0:
        return target
    best = points[np.argmin(np.abs(points - target))]
    return int(best) if abs(best - target) <= radius else target


PLACEMENTS = ("split", "turn", "pause", "onset")


def shipped_stage(p: dict) -> str:
    """The placement step (of ``PLACEMENTS``) whose estimate the detector cuts at:
    ``onset`` with ``p["onset"]``, else ``pause``."""
    return "onset" if p["onset"] else "pause"


def pose_speeds(x: np.ndarray, fps: float) -> tuple[np.ndarray, np.ndarray]:
    """The two pose speeds placement reads: low-passed at 1 Hz (pauses) and the speed of
    the poses low-passed at 3 Hz (``fine_speed``: turning points, onsets)."""
    speed = features.lowpass(features.frame_speed(x, fps=fps), fps=fps, cutoff_hz=1.0)
    return speed, fine_speed(x, fps=fps)


def place_stages(x: np.ndarray, peaks: np.ndarray, fps: float, gamma: float, p: dict,
                 speeds: tuple[np.ndarray, np.ndarray] | None = None):
    """Each placement step's estimate of every cut (see the module docstring, step 5).

    ``speeds``: ``pose_speeds(x, fps)`` when already computed (tuning places many sets
    of peaks on one take).

    Returns
    -------
    stages : {"split", "turn", "pause", "onset"} -> (n_cuts,) int frames of ``x``, each
        step starting from the previous one's result.
    speed : (n,) the 1 Hz pose speed.
    """
    speed, fine = pose_speeds(x, fps) if speeds is None else speeds
    step = max(1, int(round(fps / SPLIT_RATE_HZ)))
    turns = speed_minima(fine)
    radius = int(round(p["refine_s"] * fps))
    context = int(round(p["scale_min_s"] * fps))
    onset_radius = int(round(ONSET_MAX_S * fps))
    stages = {name: [] for name in PLACEMENTS}
    for i, cut in enumerate(int(c) for c in peaks):
        # Never look past half-way to a neighbouring cut: that stretch is theirs.
        lo = max(0, cut - context, (int(peaks[i - 1]) + cut) // 2 if i else 0)
        hi = min(len(x), cut + context)
        if i + 1 < len(peaks):
            hi = min(hi, (cut + int(peaks[i + 1])) // 2)
        split = best_split(x, cut, lo, hi, step=step, radius=radius, gamma=gamma)
        turn = nearest(turns, split, radius)
        pause = settle_frame(speed, turn, radius, context)
        stages["split"].append(split)
        stages["turn"].append(turn)
        stages["pause"].append(pause)
        limit = (cut + int(peaks[i + 1])) // 2 if i + 1 < len(peaks) else len(x) - 1
        stages["onset"].append(onset_frame(fine, pause, min(limit, pause + onset_radius),
                                           context))
    return {k: np.asarray(v, dtype=np.int64) for k, v in stages.items()}, speed


def window_widths(scale_min_s: float, scale_max_s: float, rate: float) -> list[int]:
    """Three window lengths evenly spread between the two scales, in samples at ``rate``."""
    scales = np.linspace(scale_min_s, scale_max_s, 3)
    return sorted({max(1, int(round(s * rate))) for s in scales})


@dataclass
class Analysis:
    """What the default detector computes before choosing cuts.

    x : (n, d) pose features of frames ``first ..`` at ``fps``; step : frames per novelty
    block; gamma : kernel 1 / bandwidth²; novelty : (n // step,) mean MMD² per block.
    """

    x: np.ndarray
    fps: float
    step: int
    first: int
    gamma: float
    novelty: np.ndarray
    timings: dict[str, float]
    # The factor the time settings were scaled by (``tempo``; 1: as given).
    tempo: float = 1.0
    # Curves of the pose blocks and kernel, computed once; none depends on the novelty
    # windows, so ``with_windows`` shares them.
    _short: dict = field(default_factory=dict, repr=False)

    def params(self, p: dict) -> dict:
        """``p`` with its time settings scaled as this analysis's windows were."""
        return scaled_times(p, self.tempo)

    @property
    def rate(self) -> float:
        """Novelty samples per second."""
        return self.fps / self.step

    @property
    def blocks(self) -> np.ndarray:
        """(n // step, d) the poses averaged into novelty blocks (computed once)."""
        if "blocks" not in self._short:
            self._short["blocks"] = block_mean(self.x, self.step)
        return self._short["blocks"]

    def short_novelty(self, window_s: float) -> np.ndarray:
        """(n // step,) MMD² with one window of ``window_s`` seconds (computed once)."""
        w = max(1, int(round(window_s * self.rate)))
        if w not in self._short:
            blocks = self.blocks
            self._short[w] = mirrored_novelties(blocks, [w], self.gamma)[0] \
                if len(blocks) >= 4 else np.zeros(len(blocks))
        return self._short[w]

    def unmatched(self, nearest_s: float) -> np.ndarray:
        """(n // step,) ``unmatched_poses`` of the novelty blocks (computed once)."""
        key = ("unmatched", nearest_s)
        if key not in self._short:
            self._short[key] = unmatched_poses(self.blocks, self.rate, self.gamma, nearest_s)
        return self._short[key]

    def supported(self, peaks: np.ndarray, level: float) -> np.ndarray:
        """(len(peaks),) bool: the peaks whose ``cross_support`` reaches ``level`` (each
        peak's computed once)."""
        known = self._short.setdefault("support", {})
        peaks = np.asarray(peaks).tolist()
        new = [k for k in dict.fromkeys(peaks) if k not in known]
        if new:
            known.update(zip(new, cross_support(self.blocks, np.asarray(new), self.rate,
                                                self.gamma).tolist(), strict=True))
        return np.asarray([known[k] >= level for k in peaks], dtype=bool)

    @property
    def speeds(self) -> tuple[np.ndarray, np.ndarray]:
        """``pose_speeds`` of the pose stream (computed once)."""
        if "speeds" not in self._short:
            self._short["speeds"] = pose_speeds(self.x, self.fps)
        return self._short["speeds"]

    def with_windows(self, *windows: tuple[float, float]) -> list[Analysis]:
        """The same pose stream and kernel with the novelty at other window lengths.

        ``windows`` are ``(scale_min_s, scale_max_s)`` pairs; all their window lengths
        share one pass over the lags (``mirrored_novelties``).
        """
        widths = [window_widths(lo, hi, self.rate) for lo, hi in windows]
        union = sorted({w for ws in widths for w in ws})
        curves = dict(zip(union, mirrored_novelties(self.blocks, union, self.gamma),
                          strict=True))
        return [replace(self, novelty=np.mean([curves[w] for w in ws], axis=0))
                for ws in widths]

    def peak_frames(self, peaks: np.ndarray) -> np.ndarray:
        """Novelty sample indices -> frames of ``x`` (block centres)."""
        return np.asarray(peaks, dtype=np.int64) * self.step + self.step // 2

    def segmentation(self, cuts: np.ndarray, confidence: np.ndarray,
                     speed: np.ndarray) -> Segmentation:
        """The result for cuts given in frames of ``x``."""
        centres = np.arange(len(self.novelty)) * self.step + self.step / 2
        curve = np.interp(np.arange(len(self.x)), centres, self.novelty)
        return Segmentation(
            cuts=np.asarray(cuts, dtype=np.int64) + self.first,
            confidence=confidence,
            signals={"novelty": full_length(curve, self.first),
                     "speed": full_length(speed, self.first)},
            timings=dict(self.timings),
        )


def empty_segmentation(take) -> Segmentation:
    """No cuts, for a take too short to compare anything."""
    return Segmentation(np.zeros(0, np.int64), np.zeros(0),
                        {"novelty": np.zeros(take.n_frames)})


# The split is searched on block means at this rate: finer than the 0.1 s that
# annotators label at, and the cut then moves to a turning point at the native rate.
SPLIT_RATE_HZ = 30.0
# Poses in the longest comparison window (rate_hz * scale_max_s); the cost of a take
# grows with its square.
MAX_WINDOW_SAMPLES = 600


class Default(Segmenter):
    name = "default"
    title = "Cutroom default (multi-scale kernel novelty)"
    description = (
        "Compares the distribution of heading-invariant poses before and after each "
        "instant (kernel MMD at 3-6 s windows); strong peaks become cuts, placed at the "
        "best two-segment split, then at the nearest turning point or pause of the "
        "motion. Parameters are in seconds and work at any frame rate."
    )
    params = {
        "threshold": Param(
            "float", 0.1, 0.0, 2.0,
            "Minimum mean MMD² (0 = same poses, 2 = disjoint) for a peak to become a cut.",
        ),
        "min_segment_s": Param("float", 1.5, 0.1, 60.0, "Minimum time between two cuts (s)."),
        # Cost grows with the square of the samples in a window (rate_hz * scale_max_s,
        # at most MAX_WINDOW_SAMPLES): the bounds keep a one-hour take within minutes.
        "scale_min_s": Param("float", 3.0, 0.2, 20.0, "Shortest comparison window (s)."),
        "scale_max_s": Param("float", 6.0, 0.2, 20.0, "Longest comparison window (s)."),
        "bandwidth": Param(
            "float", 0.3, 0.01, 100.0,
            "Kernel width² as a multiple of the median squared pose distance.",
        ),
        "velocity_s": Param(
            "float", 0.0, 0.0, 5.0,
            "Weight (s) of joint velocities beside the poses; 0 compares poses only.",
        ),
        "refine_s": Param(
            "float", 0.5, 0.0, 5.0,
            "How far (s) each placement step (best split, turning point, pause) may move a cut.",
        ),
        "rate_hz": Param("float", 10.0, 1.0, 60.0, "Pose rate (Hz) for the novelty curve."),
        "prominence": Param(
            "float", 0.1, 0.0, 2.0,
            "Minimum rise of a peak above the higher of the two valleys beside it (MMD²).",
        ),
        "onset": Param(
            "bool", True, 0, 1,
            "Move a cut that falls in a pause to its end, the onset of the next activity.",
        ),
        "short_activity": Param(
            "float", 0.0, 0.0, 100.0,
            "Also cut the far side of an activity shorter than the shortest window when "
            "min_segment_s windows show it this many times more clearly than the "
            "changes inside activities (0 = off).",
        ),
        "short_uniformity": Param(
            "float", 0.0, 0.0, 10.0,
            "With short_activity: keep such a cut only if the short activity's two halves "
            "differ at most this fraction as much as it differs from its neighbours "
            "(0 = no test).",
        ),
        "short_unmatched": Param(
            "float", 1.0, 0.0, 100.0,
            "Cut both sides of a short activity where the poses near a cut are this far "
            "(squared kernel widths) from every pose min_segment_s to 8 s around them "
            "(0 = off).",
        ),
        "support": Param(
            "float", 0.5, 0.0, 100.0,
            "Drop a peak where every pose of the 4 s on either side has a look-alike on "
            "the other side: the mean squared distance (squared kernel widths) from each "
            "pose to its nearest across the peak stays below this on both sides (0 = off).",
        ),
        "tempo": Param(
            "bool", False, 0, 1,
            "Scale the windows, the minimum segment and the placement reach by the "
            "take's movement cycle (a slower performer gets longer windows).",
        ),
    }

    @classmethod
    def validate_params(cls, values):
        p = super().validate_params(values)
        if p["rate_hz"] * p["scale_max_s"] > MAX_WINDOW_SAMPLES:
            raise ParamError(
                f"rate_hz: rate_hz * scale_max_s must be at most {MAX_WINDOW_SAMPLES} poses "
                f"per window, got {p['rate_hz']:g} * {p['scale_max_s']:g}"
            )
        return p

    def _segment(self, take, **p) -> Segmentation:
        analysis = self.analyse(take, p)
        if analysis is None:
            return empty_segmentation(take)
        p = analysis.params(p)
        t0 = time.perf_counter()
        peaks, strength = self.choose_peaks(analysis, p)
        cuts, speed = self._place(analysis.x, analysis.peak_frames(peaks), analysis.fps,
                                  analysis.gamma, p)
        result = analysis.segmentation(cuts, confidence(strength, p), speed)
        result.timings["cuts"] = time.perf_counter() - t0
        return result

    @classmethod
    def analyse(cls, take, p: dict) -> Analysis | None:
        """Pose stream, kernel and novelty curve of ``take`` (None if it is too short).

        ``p`` are validated parameters; a scale error raises ParamError.
        """
        if p["scale_max_s"] < p["scale_min_s"]:
            raise ParamError(
                f"scale_max_s: must be at least scale_min_s ({p['scale_min_s']:g}), "
                f"got {p['scale_max_s']:g}"
            )
        fps = float(take.fps)
        t0 = time.perf_counter()
        x, first = take_features(take, velocity_s=p["velocity_s"])
        t1 = time.perf_counter()
        step = max(1, int(round(fps / p["rate_hz"])))
        if len(x) < 2 * step:  # too short to compare anything: no cuts
            return None
        scale = tempo_scale(x, fps) if p.get("tempo") else 1.0
        p = scaled_times(p, scale)
        blocks = block_mean(x, step)
        # One kernel for detection and placement, its width from the median heuristic.
        gamma = 1.0 / max(p["bandwidth"] * median_sq_distance(blocks), 1e-12)
        novelty = cls._novelty(blocks, fps / step, gamma, p)
        t2 = time.perf_counter()
        return Analysis(x=x, fps=fps, step=step, first=first, gamma=gamma, novelty=novelty,
                        timings={"kinematics": t1 - t0, "novelty": t2 - t1},
                        tempo=scale, _short={"blocks": blocks})

    @staticmethod
    def _place(x: np.ndarray, peaks: np.ndarray, fps: float, gamma: float, p: dict):
        """Re-estimate each cut: best split, nearest turning point, nearby pause.

        Returns the placed cuts (frames of ``x``) and the 1 Hz pose speed.
        """
        stages, speed = place_stages(x, peaks, fps, gamma, p)
        return stages[shipped_stage(p)], speed

    @staticmethod
    def _novelty(x: np.ndarray, rate: float, gamma: float, p: dict) -> np.ndarray:
        """Mean MMD² over window lengths evenly spread between the two scales."""
        if len(x) < 4:
            return np.zeros(len(x))
        widths = window_widths(p["scale_min_s"], p["scale_max_s"], rate)
        return np.mean(mirrored_novelties(x, widths, gamma), axis=0)

    @classmethod
    def choose_peaks(cls, analysis: Analysis, p: dict) -> tuple[np.ndarray, np.ndarray]:
        """The novelty peaks that become cuts (``window_peaks``, then, with
        ``short_unmatched``, both sides of short activities), and their evidence."""
        peaks, strength = cls.window_peaks(analysis, p)
        if p["short_unmatched"] > 0:
            peaks, strength = unmatched_peaks(analysis, peaks, strength, p)
        return peaks, strength

    @classmethod
    def window_peaks(cls, analysis: Analysis, p: dict) -> tuple[np.ndarray, np.ndarray]:
        """The peaks the novelty windows choose (``select_peaks``, then, with
        ``short_activity``, the far sides of short activities), and their evidence."""
        peaks, strength = cls.select_peaks(analysis.novelty, analysis.rate, p)
        keep = supported_peaks(analysis, peaks, p)
        peaks, strength = peaks[keep], strength[keep]
        if p["short_activity"] > 0:
            peaks, strength = short_activity_peaks(analysis, peaks, strength, p)
        return peaks, strength

    @staticmethod
    def select_peaks(novelty: np.ndarray, rate: float, p: dict) -> tuple[np.ndarray, np.ndarray]:
        """Novelty peaks that become cuts, and each one's evidence (its prominence).

        A peak must reach ``threshold``, stand ``prominence`` above the higher of the
        valleys beside it, and lie ``min_segment_s`` from a higher peak.
        """
        # Zero guards let a peak sit on the first or last sample.
        padded = np.concatenate([[0.0], novelty, [0.0]])
        distance = max(1, int(round(p["min_segment_s"] * rate)))
        peaks, props = find_peaks(padded, height=max(p["threshold"], 1e-12),
                                  distance=distance, prominence=p["prominence"])
        peaks, prominence = peaks - 1, props["prominences"]
        # The first and last segment may be shorter than the others, but not absurdly:
        # at least half the minimum segment.
        edge = p["min_segment_s"] * rate / 2
        keep = (peaks + 0.5 >= edge) & (len(novelty) - peaks - 0.5 >= edge)
        return peaks[keep], prominence[keep]


# How far (s) a short-window peak may lie from the long-window peak or shoulder it confirms.
SHORT_PEAK_TOLERANCE_S = 0.5


def short_activity_peaks(analysis: Analysis, peaks: np.ndarray, strength: np.ndarray,
                         p: dict) -> tuple[np.ndarray, np.ndarray]:
    """Add the far side of activities too short for the long windows (step 4b).

    Between two long activities, windows of ``scale_min_s`` and more see a short one as
    a single broad peak: the boundary it does not pick is at most a *shoulder* (a local
    maximum without the prominence) at most ``scale_min_s`` away. Windows of
    ``min_segment_s`` (the shortest activity to find) resolve the two. Such a shoulder
    becomes a cut, at its short-window peak, when the short-window novelty has a peak
    within ``SHORT_PEAK_TOLERANCE_S`` of both the shoulder and the kept peak, each
    ``short_activity`` times as prominent as the median short-window peak inside the
    activities (farther than ``scale_min_s / 2`` from every kept peak) and at least
    ``prominence``: short windows also fire on changes within an activity, so only a
    pair that stands well above the take's own such changes counts. With
    ``short_uniformity`` the stretch between the two must also look like one activity
    (``mixing`` at most that), not like the passage from one activity into the next.

    Returns
    -------
    peaks, evidence : as ``Default.select_peaks``, sorted; an added peak's evidence is the
        ``prominence`` setting (confidence 0.5, the weakest peak kept on its own).
    """
    if len(peaks) == 0:
        return peaks, strength
    rate, novelty = analysis.rate, analysis.novelty
    short = analysis.short_novelty(p["min_segment_s"])
    tops, props = find_peaks(np.concatenate([[0.0], short, [0.0]]), prominence=0.0)
    tops, prominence = tops - 1, props["prominences"]
    reach = p["scale_min_s"] * rate
    inside = np.abs(tops[:, None] - peaks[None, :]).min(axis=1) > reach / 2
    if not inside.any():
        return peaks, strength
    level = max(p["short_activity"] * float(np.median(prominence[inside])), p["prominence"])
    strong = tops[prominence >= level]
    tolerance = SHORT_PEAK_TOLERANCE_S * rate
    distance = p["min_segment_s"] * rate

    def confirmed(sample: int) -> int | None:
        if not len(strong):
            return None
        best = strong[np.argmin(np.abs(strong - sample))]
        return int(best) if abs(best - sample) <= tolerance else None

    shoulders, _ = find_peaks(np.concatenate([[0.0], novelty, [0.0]]),
                              height=max(p["threshold"], 1e-12))
    cuts = list(peaks)
    for shoulder in shoulders - 1:
        kept = int(peaks[np.argmin(np.abs(peaks - shoulder))])
        if np.abs(np.asarray(cuts) - shoulder).min() < distance or \
                abs(shoulder - kept) > reach or confirmed(kept) is None:
            continue
        side = confirmed(shoulder)
        if side is None or np.abs(np.asarray(cuts) - side).min() < distance:
            continue
        if p["short_uniformity"] > 0 and not (
                mixing(analysis, kept, side, int(round(distance))) <= p["short_uniformity"]):
            continue
        cuts.append(side)
    added = np.asarray(cuts[len(peaks):], dtype=np.int64)
    order = np.argsort(np.concatenate([peaks, added]), kind="stable")
    evidence = np.concatenate([strength, np.full(len(added), p["prominence"])])
    return np.concatenate([peaks, added])[order], evidence[order]


# The support test: the stretch (s) on each side of a peak whose poses are compared, and
# the gap (s) left out around the peak itself, where the passage between two activities
# mixes both.
SUPPORT_SIDE_S = 4.0
SUPPORT_GAP_S = 0.25


def cross_support(blocks: np.ndarray, peaks: np.ndarray, rate: float, gamma: float,
                  side_s: float = SUPPORT_SIDE_S, gap_s: float = SUPPORT_GAP_S) -> np.ndarray:
    """How much of each side of each peak the other side lacks.

    For the poses (blocks) of the ``side_s`` after a peak (beyond ``gap_s``), the mean of
    ``gamma`` times the squared distance to the nearest pose of the ``side_s`` before it,
    and the same the other way; the larger of the two. A boundary between two activities
    leaves poses on at least one side that the other side never takes (high); a peak
    inside one activity whose windows caught different phases or proportions of the same
    movement has every pose matched across it (near 0), whatever the proportions.

    Returns
    -------
    (len(peaks),) float; inf where a side holds fewer than 3 blocks (a peak near an end
    of the take: nothing to say).
    """
    n = len(blocks)
    side = max(3, int(round(side_s * rate)))
    gap = int(round(gap_s * rate))
    out = np.full(len(peaks), np.inf)
    for i, k in enumerate(np.asarray(peaks, dtype=np.int64).tolist()):
        after = blocks[min(n, k + 1 + gap):min(n, k + 1 + gap + side)]
        before = blocks[max(0, k - gap - side):max(0, k - gap)]
        if len(after) < 3 or len(before) < 3:
            continue
        d = gamma * cdist(after, before, "sqeuclidean")
        out[i] = max(d.min(axis=1).mean(), d.min(axis=0).mean())
    return out


def supported_peaks(analysis: Analysis, peaks: np.ndarray, p: dict,
                    short: dict | None = None) -> np.ndarray:
    """(len(peaks),) bool: the peaks the support test keeps (step 4a; all of them with
    ``support`` 0): those whose ``cross_support`` reaches ``p["support"]``, and those the
    unmatched-poses step reads as a short activity (step 4c; ``short``, its
    ``unmatched_sides``, computed on ``peaks`` when not given): one between two alike
    activities straddles the peak, each side holds part of it, and every pose is matched
    across."""
    if p["support"] <= 0:
        return np.ones(len(peaks), dtype=bool)
    keep = analysis.supported(peaks, p["support"])
    if not keep.all():
        short = unmatched_sides(analysis, peaks, p) if short is None else short
        keep |= np.isin(peaks, list(short))
    return keep


# Step 4c: how far around a pose (s) its look-alikes are sought, the stretch (s) whose
# poses must all be unmatched, how far from a kept peak (s) that stretch may lie, and
# how far (s) each side of the stretch's middle its two cuts are placed from, and how
# many times the take's median unmatched level the stretch must reach as well.
UNMATCHED_CONTEXT_S = 8.0
UNMATCHED_STRETCH_S = 1.2
UNMATCHED_REACH_S = 1.5
UNMATCHED_HALF_S = 1.25
UNMATCHED_RELATIVE = 2.3


def unmatched_poses(blocks: np.ndarray, rate: float, gamma: float, nearest_s: float,
                    context_s: float = UNMATCHED_CONTEXT_S) -> np.ndarray:
    """How unlike every pose around it each pose is.

    For each block, ``gamma`` times the squared distance to the most similar block
    ``nearest_s`` to ``context_s`` seconds before or after it (in squared kernel widths:
    1 is a kernel similarity of e^-1). Inside a repeating activity some pose a cycle or
    two away always looks alike (near 0); inside an activity shorter than twice
    ``nearest_s`` between two others, every pose the search reaches belongs to the
    neighbours, and none looks alike.

    Returns
    -------
    (n_blocks,) float; 0 for a block with nothing in reach (a take too short to say).
    """
    n = len(blocks)
    out = np.full(n, np.inf)
    lo = max(1, int(np.ceil(nearest_s * rate - 1e-9)))
    hi = min(n - 1, int(np.floor(context_s * rate + 1e-9)))
    for lag in range(lo, hi + 1):
        diff = blocks[lag:] - blocks[:-lag]
        d = np.einsum("ij,ij->i", diff, diff)
        np.minimum(out[lag:], d, out=out[lag:])
        np.minimum(out[:-lag], d, out=out[:-lag])
    out[~np.isfinite(out)] = 0.0
    return gamma * out


def unmatched_peaks(analysis: Analysis, peaks: np.ndarray, strength: np.ndarray,
                    p: dict, half_s: float = UNMATCHED_HALF_S,
                    relative: float = UNMATCHED_RELATIVE) -> tuple[np.ndarray, np.ndarray]:
    """Both sides of a short activity the long windows see as one peak (step 4c).

    Each kept peak that ``unmatched_sides`` finds beside a short activity is replaced by
    that activity's two sides. Where two cuts end up closer than ``min_segment_s``, the
    earlier is kept.

    Returns
    -------
    peaks, evidence : as ``Default.select_peaks``, sorted; both sides keep the evidence
        of the peak they replace.
    """
    sides = unmatched_sides(analysis, peaks, p, half_s, relative)
    out = sorted((side, evidence) for peak, evidence in zip(peaks.tolist(), strength.tolist(),
                                                            strict=True)
                 for side in sides.get(peak, (peak,)))
    kept: list[tuple[int, float]] = []
    for peak, evidence in out:
        if not kept or peak - kept[-1][0] >= p["min_segment_s"] * analysis.rate - 1e-9:
            kept.append((peak, evidence))
    return (np.asarray([k for k, _ in kept], dtype=peaks.dtype),
            np.asarray([e for _, e in kept], dtype=float))


def unmatched_sides(analysis: Analysis, peaks: np.ndarray, p: dict,
                    half_s: float = UNMATCHED_HALF_S,
                    relative: float = UNMATCHED_RELATIVE) -> dict[int, tuple[int, int]]:
    """The kept peaks that stand for a short activity of their own, and its two sides.

    Near each kept peak (``UNMATCHED_REACH_S``), the stretch of ``UNMATCHED_STRETCH_S``
    whose poses are, on average, least like any pose ``min_segment_s`` to
    ``UNMATCHED_CONTEXT_S`` around them (``unmatched_poses``). When that average is at
    least ``short_unmatched`` and ``relative`` times the take's median, the stretch is
    the middle of an activity of its own, too short to hold a look-alike of its own
    poses: its sides are at the stretch's middle ± ``half_s`` (placement then moves each
    to its boundary). The median is how unmatched the take's poses are anyway: in a
    take that does not repeat itself (boxing, dance, a fight) no pose has a look-alike
    and a stretch near the absolute level says nothing. Not when kept peaks lie on
    both sides of the stretch within ``scale_min_s``: the long windows have found that
    activity's two sides already, and a longer activity that does not repeat within a
    few seconds (a slow exercise) looks unmatched too. Not either when a side would lie
    closer than ``min_segment_s / 2`` to an end of the take.

    Returns
    -------
    kept peak (novelty sample) -> (first side, second side), novelty samples.
    """
    if len(peaks) == 0 or p["short_unmatched"] <= 0:
        return {}
    firings, median = unmatched_firings(analysis, peaks, p, half_s)
    level = max(p["short_unmatched"], relative * median)
    return {peak: sides for peak, (sides, at) in firings.items() if at >= level}


def unmatched_firings(analysis: Analysis, peaks: np.ndarray, p: dict,
                      half_s: float = UNMATCHED_HALF_S
                      ) -> tuple[dict[int, tuple[tuple[int, int], float]], float]:
    """``unmatched_sides`` before its level test: each kept peak whose most unmatched
    stretch in reach passes the other tests, with its two sides and the stretch's mean
    ``unmatched_poses``; and the take's median of ``unmatched_poses`` per block."""
    rate = analysis.rate
    unmatched = analysis.unmatched(p["min_segment_s"])
    w = max(1, int(round(UNMATCHED_STRETCH_S * rate)))
    if len(unmatched) < w:
        return {}, 0.0
    sums = np.concatenate([[0.0], np.cumsum(unmatched)])
    stretch = (sums[w:] - sums[:-w]) / w  # mean over blocks i .. i + w - 1
    reach, half = UNMATCHED_REACH_S * rate, half_s * rate
    edge = p["min_segment_s"] * rate / 2
    out = {}
    for peak in peaks.tolist():
        lo = max(0, int(peak - reach) - w // 2)
        hi = min(len(stretch), int(peak + reach) - w // 2 + 1)
        if hi <= lo:
            continue
        start = lo + int(np.argmax(stretch[lo:hi]))
        middle = start + w // 2
        # Kept peaks on both sides within the shortest window: the long windows have
        # found this activity's two sides already.
        near = np.abs(peaks - middle) <= p["scale_min_s"] * rate
        if (near & (peaks < middle)).any() and (near & (peaks > middle)).any():
            continue
        sides = (int(round(middle - half)), int(round(middle + half)))
        if edge <= sides[0] and sides[1] <= len(unmatched) - edge:
            out[int(peak)] = (sides, float(stretch[start]))
    return out, float(np.median(unmatched))


def mixing(analysis: Analysis, a: int, b: int, context: int) -> float:
    """How unlike itself the stretch between novelty samples ``a`` and ``b`` is.

    MMD² between the stretch's two halves over MMD² between the stretch and the nearer-
    looking of its neighbours (``context`` samples each side), on the novelty blocks and
    kernel. An activity repeats, so its halves look alike (near 0); the passage from one
    activity into the next morphs, so its halves differ about as much as it differs from
    its neighbours (near 1 and above). NaN when a part is too short to compare.
    """
    lo, hi = sorted((a, b))
    blocks = analysis.blocks
    middle, before, after = blocks[lo:hi], blocks[max(0, lo - context):lo], blocks[hi:hi + context]
    if len(middle) < 4 or min(len(before), len(after)) < 2:
        return float("nan")
    half = len(middle) // 2
    inner = mmd(middle[:half], middle[half:], analysis.gamma)
    return inner / max(min(mmd(before, middle, analysis.gamma),
                           mmd(middle, after, analysis.gamma)), 1e-12)


def mmd(x: np.ndarray, y: np.ndarray, gamma: float) -> float:
    """Biased MMD² between the samples ``x`` (n, d) and ``y`` (m, d), Gaussian kernel."""
    def mean_k(u, v):
        return float(np.exp(-gamma * cdist(u, v, "sqeuclidean")).mean())
    return mean_k(x, x) + mean_k(y, y) - 2 * mean_k(x, y)


def confidence(evidence: np.ndarray, p: dict) -> np.ndarray:
    """Peak prominence -> confidence in [0, 1): 0.5 at the ``prominence`` setting."""
    half = p["prominence"] if p["prominence"] > 0 else p["threshold"]
    return evidence / (evidence + max(half, 1e-12))
