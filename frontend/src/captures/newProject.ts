// Creating a project from the capture list. The API lets anyone signed in create one and
// makes them its admin; from there they add labels and invite people on the Team page.

import { post } from "../api/client";
import type { Project } from "../api/types";
import { h, toast } from "../ui/dom";
import { promptDialog } from "../ui/prompt";

/** Ask for a name, create the project, then show the list filtered to it (loaded afresh,
 * so every menu knows the new project and the caller's admin role in it). */
async function createProject(): Promise<void> {
  const name = await promptDialog("New project", "You become its admin: add its labels and invite people from its Team page.", "Create project", "Project name");
  if (!name) return;
  try {
    const project = await post<Project>("/api/projects/", { name });
    location.assign(`/?project=${project.id}`);
  } catch (err) {
    toast(`Could not create ${name}: ${(err as Error).message}`, "error");
  }
}

export function newProjectButton(): HTMLElement {
  return h("button", { class: "btn", "data-testid": "new-project", title: "Create a project of your own; you become its admin", onclick: () => void createProject() }, "New project");
}
