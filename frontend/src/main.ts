import "./style.css";
import { renderCaptureList } from "./captures/list";
import { registerLibraryRoutes } from "./library/routes";
import { renderQueue } from "./queue/page";
import { renderReview } from "./review/page";
import { renderTeam } from "./team/page";
import { registerRoute, start } from "./router";

registerRoute("/", (root) => renderCaptureList(root));
registerRoute("/captures/", (root) => renderCaptureList(root));
registerRoute("/captures/:id/", (root, params) => renderReview(root, Number(params.id)));
registerLibraryRoutes();
registerRoute("/queue/", (root) => renderQueue(root));
registerRoute("/projects/:id/team/", (root, params) => renderTeam(root, Number(params.id)));

start(document.getElementById("app")!);
