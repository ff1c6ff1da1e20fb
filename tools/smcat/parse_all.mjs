// Parse .smcat files with state-machine-cat itself, in one process (the tests' check that every
// file fsmbt writes is state-machine-cat): stdin a JSON list of paths, stdout a JSON list of
// {ok, ast} / {ok: false, error} in the same order.
import { render } from "state-machine-cat";
import { readFileSync } from "node:fs";

const files = JSON.parse(readFileSync(0, "utf8"));
const out = [];
for (const file of files) {
  try {
    const ast = await render(readFileSync(file, "utf8"), { inputType: "smcat", outputType: "json" });
    out.push({ ok: true, ast: typeof ast === "string" ? JSON.parse(ast) : ast });
  } catch (error) {
    out.push({ ok: false, error: String(error.message || error).split("\n")[0] });
  }
}
process.stdout.write(JSON.stringify(out));
