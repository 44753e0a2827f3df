from django.contrib import admin
from django.contrib.auth import get_user_model
from django.contrib.auth.admin import UserAdmin
from django.contrib.auth.forms import AdminUserCreationForm, UserChangeForm
from django.core.exceptions import ValidationError

from accounts import usernames
from accounts.models import ApiToken, LoginFailure


class CheckedUsername:
    """A user form's username goes through ``usernames``: stored stripped and in NFKC,
    refused if it holds invisible or look-alike characters or is another account's name
    in another case or form."""

    def clean_username(self):
        try:
            name = usernames.clean(self.cleaned_data.get("username"))
            usernames.check_available(name, exclude=self.instance)
        except usernames.UsernameError as exc:
            raise ValidationError(f"Username {exc}.", code="username") from None
        return name


class NewUserForm(CheckedUsername, AdminUserCreationForm):
    pass


class ChangeUserForm(CheckedUsername, UserChangeForm):
    pass


admin.site.unregister(get_user_model())


@admin.register(get_user_model())
class CheckedUserAdmin(UserAdmin):
    add_form = NewUserForm
    form = ChangeUserForm


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
