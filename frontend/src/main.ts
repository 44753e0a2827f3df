import "./style.css";
import { renderCaptureList } from "./captures/list";
import { registerLibraryRoutes } from "./library/routes";
import { renderReview } from "./review/page";
import { registerRoute, start } from "./router";

registerRoute("/", (root) => renderCaptureList(root));
registerRoute("/captures/", (root) => renderCaptureList(root));
registerRoute("/captures/:id/", (root, params) => renderReview(root, Number(params.id)));
registerLibraryRoutes();

start(document.getElementById("app")!);
