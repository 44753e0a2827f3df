// Routes of the library pages, registered by main.ts before the router starts.

import { registerRoute } from "../router";
import { renderAdjudication } from "../adjudicate/page";
import { renderDashboard } from "./dashboard";
import { renderLibrary } from "./page";

export function registerLibraryRoutes(): void {
  registerRoute("/library/", (root) => renderLibrary(root));
  registerRoute("/captures/:id/adjudicate/", (root, params) => renderAdjudication(root, Number(params.id)));
  registerRoute("/projects/:id/dashboard/", (root, params) => renderDashboard(root, Number(params.id)));
}
