from django.contrib.auth import get_user_model
from django.core.management.base import BaseCommand, CommandError

from accounts import usernames


class Command(BaseCommand):
    help = (
        "List accounts whose usernames today's rules would refuse (invisible or look-alike "
        "characters) or that share their key with an older account, made before the rules; "
        "exit 1 when there are any. Rename them in the admin."
    )

    def handle(self, *args, **options):
        found = 0
        users = get_user_model()._default_manager.order_by("pk")
        for user in users.select_related("username_key").iterator():
            problem = _problem(user)
            if problem:
                found += 1
                self.stdout.write(f"account {user.pk} {user.username!r}: {problem}")
        if found:
            raise CommandError(f"{found} account(s) to rename")
        self.stdout.write("every username follows the rules")


def _problem(user):
    try:
        usernames.clean(user.username)
    except usernames.UsernameError as exc:
        return str(exc)
    stored = getattr(user, "username_key", None)
    if stored is None or stored.digest is None:
        older = get_user_model()._default_manager.filter(
            username_key__digest=usernames.digest(user.username)).exclude(pk=user.pk).first()
        return (f"differs only in case or form from account {older.pk} {older.username!r}; "
                "it signs in by its exact name only") if older else "has no stored key"
    return None
