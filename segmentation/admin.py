from django.contrib import admin

from segmentation.models import (
    Capture,
    Cut,
    DetectionRun,
    Invitation,
    Label,
    Membership,
    Project,
    ProjectCutModel,
    Review,
    ReviewEvent,
    SegmentLabel,
)


class MembershipInline(admin.TabularInline):
    model = Membership
    extra = 0


class LabelInline(admin.TabularInline):
    model = Label
    extra = 0


@admin.register(Project)
class ProjectAdmin(admin.ModelAdmin):
    list_display = ("name", "default_method", "created_at")
    search_fields = ("name",)
    inlines = (MembershipInline, LabelInline)


@admin.register(Membership)
class MembershipAdmin(admin.ModelAdmin):
    list_display = ("project", "user", "role")
    list_filter = ("role",)


@admin.register(Invitation)
class InvitationAdmin(admin.ModelAdmin):
    """The record of who invited whom, and what became of it; read-only."""

    list_display = ("username", "project", "role", "status", "invited_by", "created_at", "answered_at")
    list_filter = ("status", "role")
    search_fields = ("username", "project__name")

    def has_add_permission(self, request):
        return False

    def has_change_permission(self, request, obj=None):
        return False

    def has_delete_permission(self, request, obj=None):
        return False


@admin.register(Label)
class LabelAdmin(admin.ModelAdmin):
    list_display = ("name", "project", "color", "hotkey")


@admin.register(Capture)
class CaptureAdmin(admin.ModelAdmin):
    list_display = ("name", "project", "format", "status", "n_frames", "fps", "created_at")
    list_filter = ("status", "format", "project")
    search_fields = ("name", "checksum")
    readonly_fields = ("checksum", "error_permanent", "claim_token", "claimed_at", "attempts")


@admin.register(ProjectCutModel)
class ProjectCutModelAdmin(admin.ModelAdmin):
    list_display = ("id", "project", "version", "status", "n_takes", "n_cuts", "held_out_edits_per_cut",
                    "held_out_f1", "refused", "created_at", "finished_at")
    list_filter = ("status", "project")
    # What the gate decided is the record of a training, not a setting to edit.
    readonly_fields = ("error_permanent", "claim_token", "claimed_at", "attempts", "trained_on",
                       "held_out_takes", "held_out_edits_per_cut", "held_out_f1", "refused")


@admin.register(DetectionRun)
class DetectionRunAdmin(admin.ModelAdmin):
    list_display = ("id", "capture", "method", "status", "created_at", "finished_at")
    list_filter = ("status", "method")
    readonly_fields = ("error_permanent", "claim_token", "claimed_at", "attempts")


class CutInline(admin.TabularInline):
    model = Cut
    extra = 0


@admin.register(Review)
class ReviewAdmin(admin.ModelAdmin):
    list_display = ("capture", "annotator", "status", "version", "updated_at")
    list_filter = ("status",)
    inlines = (CutInline,)


@admin.register(Cut)
class CutAdmin(admin.ModelAdmin):
    list_display = ("id", "review", "origin", "fate", "candidate_frame", "frame", "confidence")
    list_filter = ("origin", "fate")


@admin.register(SegmentLabel)
class SegmentLabelAdmin(admin.ModelAdmin):
    list_display = ("review", "cut", "label")


@admin.register(ReviewEvent)
class ReviewEventAdmin(admin.ModelAdmin):
    list_display = ("created_at", "review", "user", "action", "cut")
    list_filter = ("action",)
    readonly_fields = ("review", "user", "action", "cut", "before", "after", "created_at")
