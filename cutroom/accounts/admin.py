from django.contrib import admin

from cutroom.accounts.models import ApiToken, LoginFailure


@admin.register(ApiToken)
class ApiTokenAdmin(admin.ModelAdmin):
    """Revoking a token is deleting it ("Delete selected API tokens", or one's page)."""

    list_display = ("prefix", "user", "created_at", "expires_at", "last_used_at")
    list_filter = ("expires_at",)
    search_fields = ("user__username", "prefix")
    readonly_fields = ("user", "prefix", "created_at", "expires_at", "last_used_at")
    exclude = ("digest",)

    def has_add_permission(self, request):
        return False  # keys are issued by POST /api/auth/token/ and shown only there


@admin.register(LoginFailure)
class LoginFailureAdmin(admin.ModelAdmin):
    """Failed sign-ins in the throttling window; deleting rows lifts a throttle early."""

    list_display = ("key", "at")
    readonly_fields = ("key", "at")

    def has_add_permission(self, request):
        return False

    def has_change_permission(self, request, obj=None):
        return False
