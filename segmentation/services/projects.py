"""Projects, their members and their label taxonomy."""

import re

from django.contrib.auth import get_user_model
from django.db import IntegrityError, transaction

from segmentation.errors import Invalid
from segmentation.limits import check_name, text_limit
from segmentation.models import Label, Membership, Project
from segmentation.services.captures import validate_method

COLOR = re.compile(r"^#[0-9a-fA-F]{6}$")


def do_create_project(user, name, default_method="", default_params=None,
                      annotators_pick_unassigned=True):
    """A new project with ``user`` as its admin; ParamError names a bad default."""
    check_name("name", name, text_limit(Project, "name"))
    params = checked_defaults(default_method, default_params)
    with transaction.atomic():
        project = Project.objects.create(
            name=name, default_method=default_method or "", default_params=params,
            annotators_pick_unassigned=annotators_pick_unassigned,
        )
        Membership.objects.create(project=project, user=user, role="admin")
    return project


def do_update_project(project, **fields):
    """Rename a project or change its default method and parameters.

    The project row is locked and read again first, so new parameters are checked against
    the method as stored by a concurrent change, not as this request last saw it.
    """
    if "name" in fields:
        check_name("name", fields["name"], text_limit(Project, "name"))
    with transaction.atomic():
        current = _locked(project)
        method = fields.get("default_method", current.default_method)
        if "default_method" in fields or "default_params" in fields:
            params = fields.get("default_params", current.default_params)
            fields["default_params"] = checked_defaults(method, params)
        for name, value in fields.items():
            setattr(project, name, value)
        project.save(update_fields=list(fields))
    return project


def _locked(project):
    """The project row, locked until the transaction ends: the changes of its members, its
    settings and its taxonomy run one after the other (see also ``services.team``)."""
    return Project.objects.select_for_update().get(pk=project.pk)


def checked_defaults(method, params):
    """The given parameters, coerced to the method's schema (an empty method means the
    registry's default). Unset parameters stay unset so they follow the method's defaults."""
    validated = validate_method(method, params)[1]
    return {key: validated[key] for key in params or {}}


def do_set_member(project, username, role):
    """Add a user to the project, or change their role; a project keeps one admin."""
    user = get_user_model().objects.filter(username=username).first()
    if user is None:
        raise Invalid(f"username: no user named {username!r}")
    with transaction.atomic():
        # The project row lock serialises role changes (see services.team).
        _locked(project)
        demoted = project.role_of(user) == "admin" and role != "admin"
        if demoted and project.memberships.filter(role="admin").count() == 1:
            raise Invalid(f"role: {username!r} is the project's only admin; add another admin first")
        membership, _ = Membership.objects.update_or_create(
            project=project, user=user, defaults={"role": role}
        )
    return membership


def do_add_label(project, name, color="#888888", hotkey=None):
    """Add a label to the taxonomy; names and hotkeys are unique within a project."""
    name = name.strip()
    if not name:
        raise Invalid("name: a label needs a name")
    check_name("name", name, text_limit(Label, "name"))
    if not COLOR.match(color or ""):
        raise Invalid(f"color: must look like #rrggbb, got {color!r}")
    if hotkey is not None and (len(hotkey) != 1 or hotkey not in "123456789"):
        raise Invalid(f"hotkey: must be one of 1..9 or null, got {hotkey!r}")
    with transaction.atomic():
        # Concurrent adds run one after the other: the second sees the first's label.
        _locked(project)
        if project.labels.filter(name=name).exists():
            raise Invalid(f"name: the project already has a label {name!r}")
        if hotkey and project.labels.filter(hotkey=hotkey).exists():
            raise Invalid(f"hotkey: {hotkey!r} is already used by another label")
        position = project.labels.count()  # new labels go to the end of the taxonomy
        try:
            with transaction.atomic():
                return Label.objects.create(project=project, name=name, color=color.lower(),
                                            hotkey=hotkey, position=position)
        except IntegrityError:
            # Where the database cannot lock the row (SQLite), a concurrent add still
            # loses to the unique constraints: say which, as the checks above would.
            if hotkey is None or project.labels.filter(name=name).exists():
                raise Invalid(f"name: the project already has a label {name!r}") from None
            raise Invalid(f"hotkey: {hotkey!r} is already used by another label") from None
