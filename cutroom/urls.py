from django.contrib import admin
from django.contrib.auth import views as auth_views
from django.urls import include, path, re_path

from cutroom.accounts.views import new_password, throttled_sign_in
from segmentation import views

urlpatterns = [
    path("admin/login/", throttled_sign_in(admin.site.login)),
    path("admin/", admin.site.urls),
    path("api/", include("cutroom.accounts.api")),
    path("api/", include("segmentation.api.urls")),
    path("login/", throttled_sign_in(auth_views.LoginView.as_view()), name="login"),
    path("password/new/", new_password, name="new-password"),
    path("logout/", views.logout_view, name="logout"),
    path("favicon.ico", views.favicon),
    path("favicon.svg", views.favicon, name="favicon"),
    path("", views.app, name="app"),
    re_path(r"^(?P<path>(captures|library|projects|queue)(/.*)?)$", views.app),
]
