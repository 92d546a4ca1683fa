// kerf page shell: the tabs and `#/view` routes (Back and Forward move between views), each view
// mounted once in its own section so its form and result stay when another view is shown.
import { decimalInputs } from '/form.js';
import { mountUnits, prepareRoot, unitsSwitch } from '/units.js';
import { VIEWS } from '/views.js';

const mounted = new Map();

// The view a location hash names: `#/deburr`, or `#deburr` (a link typed or kept without the
// slash still opens its view); else the first.
function routed() {
  const id = location.hash.replace(/^#\/?/, '');
  return VIEWS.find((v) => v.id === id) || VIEWS[0];
}

function show(view) {
  const tabs = document.getElementById('tabs');
  for (const link of tabs.querySelectorAll('a')) {
    if (link.dataset.view !== view.id) {
      link.removeAttribute('aria-current');
      continue;
    }
    link.setAttribute('aria-current', 'page');
    // On a phone the tabs scroll sideways in their row: bring the current one into the middle.
    const [row, tab] = [tabs.getBoundingClientRect(), link.getBoundingClientRect()];
    tabs.scrollLeft += tab.left - row.left - (row.width - tab.width) / 2;
  }
  const main = document.getElementById('view');
  for (const section of main.children) section.hidden = section.dataset.viewRoot !== view.id;
  let root = mounted.get(view.id);
  if (!root) {
    root = document.createElement('section');
    root.dataset.viewRoot = view.id;
    root.setAttribute('aria-label', view.title);
    main.append(root);
    mounted.set(view.id, root);
    decimalInputs(root);
    prepareRoot(root, view.id);
    view.mount(root, view.id);
    mountUnits(root, view.id);
  } else {
    root.dispatchEvent(new Event('kerf:show'));
  }
  document.title = `${view.title} – kerf`;
}

document.getElementById('token-box').addEventListener('submit', (event) => {
  event.preventDefault();
  localStorage.setItem('kerf-token', event.target.elements.token.value.trim());
  event.target.hidden = true;
});

unitsSwitch();
const tabs = document.getElementById('tabs');
for (const view of VIEWS) {
  const link = document.createElement('a');
  link.textContent = view.title;
  link.href = `#/${view.id}`;
  link.dataset.view = view.id;
  tabs.append(link);
}
window.addEventListener('hashchange', () => show(routed()));
if (!/^#\//.test(location.hash)) history.replaceState(null, '', `#/${routed().id}`);
show(routed());
