// Bundles the page: node build.mjs MODULES_DIR OUT_DIR
// MODULES_DIR holds the node_modules that `npm ci` installed from package-lock.json (the
// build tree's, never the repository's); OUT_DIR receives index.html and
// assets/{app.js,app.css}, the directory `thzmap serve` serves.
import { createRequire } from "node:module";
import { copyFileSync, mkdirSync } from "node:fs";
import { dirname, join, resolve } from "node:path";
import { fileURLToPath } from "node:url";

const [modules, out] = process.argv.slice(2).map((p) => resolve(p));
if (!modules || !out) {
  console.error("usage: node build.mjs MODULES_DIR OUT_DIR");
  process.exit(2);
}
const here = dirname(fileURLToPath(import.meta.url));
const esbuild = createRequire(join(modules, "package.json"))("esbuild");
mkdirSync(join(out, "assets"), { recursive: true });
await esbuild.build({
  entryPoints: [join(here, "src", "main.js")],
  bundle: true,
  minify: true,
  format: "esm",
  target: "es2020",
  nodePaths: [modules],
  outfile: join(out, "assets", "app.js"),
  logLevel: "warning",
});
copyFileSync(join(here, "src", "index.html"), join(out, "index.html"));
copyFileSync(join(here, "src", "app.css"), join(out, "assets", "app.css"));
