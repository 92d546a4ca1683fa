// kerf's list of views, in tab order: the one place that names them. Each entry gives the route
// id (`#/deburr`), the tab title, the form view's `mount(root, id)` and, for a capability, how its
// answer is shown (`result(container, answer)`, also used for job results). Later generated from
// the server's capability registry.
import { contourResult, contourView } from '/views/contour.js';
import { deburrResult, deburrView } from '/views/deburr.js';
import { engagementResult, engagementView } from '/views/engagement.js';
import { jobsView } from '/views/jobs.js';
import { machinesView } from '/views/machines.js';
import { predictResult, predictView } from '/views/predict.js';
import { segmentResult, segmentView } from '/views/segment.js';
import { toolsView } from '/views/tools.js';

export const VIEWS = [
  { id: 'deburr', title: 'Deburr', mount: deburrView.mount, result: deburrResult },
  { id: 'segment', title: 'Segment', mount: segmentView.mount, result: segmentResult },
  { id: 'contour', title: 'Contour', mount: contourView.mount, result: contourResult },
  { id: 'engagement', title: 'Engagement', mount: engagementView.mount, result: engagementResult },
  { id: 'predict', title: 'Predict', mount: predictView.mount, result: predictResult },
  { id: 'jobs', title: 'Jobs', mount: jobsView.mount },
  { id: 'tools', title: 'Tools', mount: toolsView.mount },
  { id: 'machines', title: 'Machines', mount: machinesView.mount },
];

// How a job's operation result is shown: the view with that id.
export function resultView(operation) {
  return VIEWS.find((v) => v.id === operation)?.result;
}
