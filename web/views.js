// kerf's list of views, in tab order. The capability views come from the server's capability
// registry (`/capabilities.js`, generated): for each name, `/views/{name}.js` exports `view` with
// its tab title, the form view's `mount(root, id)` and how its answer is shown (`result(container,
// answer)`, also used for job results). The other views are listed here.
import { CAPABILITIES } from '/capabilities.js';
import { jobsView } from '/views/jobs.js';
import { machinesView } from '/views/machines.js';
import { materialsView } from '/views/materials.js';
import { toolsView } from '/views/tools.js';

// A capability whose view does not load is left out (and reported) instead of breaking the page.
const capabilityViews = (await Promise.all(CAPABILITIES.map(async (id) => {
  try {
    const { view } = await import(`/views/${id}.js`);
    return { id, ...view };
  } catch (error) {
    console.error(`the view of capability ${id} did not load`, error);
    return null;
  }
}))).filter(Boolean);

export const VIEWS = [
  ...capabilityViews,
  { id: 'jobs', title: 'Jobs', mount: jobsView.mount },
  { id: 'tools', title: 'Tools', mount: toolsView.mount },
  { id: 'machines', title: 'Machines', mount: machinesView.mount },
  { id: 'materials', title: 'Materials', mount: materialsView.mount },
];

// How a job's operation result is shown: the view with that id.
export function resultView(operation) {
  return VIEWS.find((v) => v.id === operation)?.result;
}
