// The page of `thzmap serve` (docs/gui.md): tabs Scene (pre-processor), Run, Results
// (post-processor). The token in the address has already become a cookie; drop it from
// the address bar so that it is not bookmarked or shared by accident.
import { getJSON, reportError, status } from "./api.js";
import { SceneEditor } from "./sceneui.js";
import { Runs } from "./runs.js";
import { Results } from "./results.js";
import { forget } from "./envi.js";

if (new URLSearchParams(location.search).has("token")) history.replaceState(null, "", "/");

function showTab(name) {
  for (const b of document.querySelectorAll("#tabs button")) b.classList.toggle("active", b.dataset.tab === name);
  for (const v of document.querySelectorAll(".view")) v.classList.toggle("active", v.id === `view-${name}`);
  window.dispatchEvent(new Event("resize"));
}
for (const b of document.querySelectorAll("#tabs button")) b.onclick = () => showTab(b.dataset.tab);

const editor = new SceneEditor();
const runs = new Runs();
const results = new Results();
window.thzmap = { editor, runs, results, showTab }; // for the console and the end-to-end test

document.addEventListener("scene-opened", (e) => runs.sceneOpened(e.detail));
runs.unsaved = (path) => editor.dirty && editor.path === path;
// edits not saved are lost with the page: the browser asks first
window.addEventListener("beforeunload", (e) => {
  if (editor.dirty) e.preventDefault();
});
// a run writes its cubes anew: drop what was read of them before (the cache is by path)
document.addEventListener("run-finished", (e) => {
  forget(`${e.detail.out.replace(/\/+$/, "")}/`);
  results.open(e.detail.out).catch(reportError);
});
document.addEventListener("show-results", (e) => {
  showTab("results");
  results.open(e.detail).catch(reportError);
});

(async () => {
  try {
    const info = await getJSON("/api/info");
    // the revision names the build between releases (docs/gui.md); a server without it
    // says the version alone
    const revision = info.revision ? ` (revision ${info.revision})` : "";
    status(`thzmap ${info.version || ""}${revision} · root ${info.root || ""}`);
    await editor.listFiles("");
    await results.browse("");
    await runs.refresh();
  } catch (e) {
    reportError(e);
  }
})();
