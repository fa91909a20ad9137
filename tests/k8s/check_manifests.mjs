// ctest k8s_manifest_check: every document of the given manifests against the Kubernetes OpenAPI
// schema of its kind (npm kubernetes-models 5.1.0, pinned by package-lock.json: the upstream
// OpenAPI definitions compiled to ajv validators), with what that schema does not say:
//  - unknown fields: the schema leaves them open, the API server refuses them (strict field
//    validation, kubectl's default --validate=strict); a misspelt backoffLimitPerIndex would
//    otherwise pass here and be refused there;
//  - the Job rules the API server adds (k8s.io/kubernetes pkg/apis/batch/validation) for the
//    fields the fleet Job relies on, and what docs/ros2.md promises of it.
// Before the manifests, each check is shown to fail on a copy with one defect (a check that
// cannot fail proves nothing).
//   node tests/k8s/check_manifests.mjs PROJECT_VERSION MANIFEST...
// Exits 77 (ctest: skipped) when the npm packages are not installed (tools/install_deps.sh --tests).
import { readFileSync } from "node:fs";

let YAML, schemas;
try {
  YAML = await import("yaml");
  schemas = {
    "batch/v1 Job": (await import("kubernetes-models/_schemas/IoK8sApiBatchV1Job")).validate,
    "v1 PersistentVolumeClaim": (
      await import("kubernetes-models/_schemas/IoK8sApiCoreV1PersistentVolumeClaim")
    ).validate,
  };
} catch (e) {
  console.log(`skipped: ${e.message} (tools/install_deps.sh --tests installs tests/k8s/node_modules)`);
  process.exit(77);
}

const [version, ...files] = process.argv.slice(2);

function schemaErrors(doc) {
  const validate = schemas[`${doc.apiVersion} ${doc.kind}`];
  if (!validate) return [`no schema here for ${doc.apiVersion} ${doc.kind}`];
  return validate(doc) ? [] : validate.errors.map((e) => `${e.instancePath} ${e.message ?? e.keyword}`);
}

// A field is one the schema knows when a value of no JSON type put there is refused at exactly
// that path: the compiled validators check the type of every known field, and none of an
// unknown one. Map values (labels, resource requests) are typed by the map's schema, so they
// count as known.
function unknownFields(doc) {
  const unknown = [];
  const walk = (node, path) => {
    if (Array.isArray(node)) {
      node.forEach((v, i) => walk(v, [...path, i]));
      return;
    }
    if (node === null || typeof node !== "object") return;
    for (const key of Object.keys(node)) {
      const at = [...path, key];
      const probe = structuredClone(doc);
      let parent = probe;
      for (const step of path) parent = parent[step];
      parent[key] = Symbol("probe");
      const pointer = "/" + at.join("/");
      const validate = schemas[`${doc.apiVersion} ${doc.kind}`];
      const refused = !validate(probe) && validate.errors.some((e) => e.instancePath === pointer);
      if (!refused) unknown.push(`${pointer}: not a field of ${doc.kind}`);
      else walk(node[key], at);
    }
  };
  walk(doc, []);
  return unknown;
}

// What the API server adds for Jobs (pkg/apis/batch/validation) and what the fleet needs.
function jobRules(job, docs) {
  const s = job.spec ?? {};
  const pod = s.template?.spec ?? {};
  const problems = [];
  const need = (ok, what) => ok || problems.push(what);
  need(s.completionMode === "Indexed", "spec.completionMode: Indexed (one index per robot)");
  need(Number.isInteger(s.backoffLimitPerIndex),
       "spec.backoffLimitPerIndex: a refused robot fails its own index, not the Job");
  need(s.backoffLimit === undefined,
       "spec.backoffLimit: leave it out (with backoffLimitPerIndex it counts every index's failures)");
  need(Number.isInteger(s.maxFailedIndexes) && s.maxFailedIndexes < s.completions - 1,
       "spec.maxFailedIndexes: set, and below the number of robots (completions - 1)");
  need(pod.restartPolicy === "Never", "restartPolicy: Never (required by podFailurePolicy)");
  for (const rule of s.podFailurePolicy?.rules ?? []) {
    const codes = rule.onExitCodes?.values ?? [];
    need(codes.every((c, i) => i === 0 || codes[i - 1] < c), "onExitCodes.values: ascending, unique");
    need(!codes.includes(0), "onExitCodes.values: 0 is success, not a failure");
    need(rule.onExitCodes?.operator !== "In" || codes.includes(5),
         "podFailurePolicy: exit 5 (refused) fails the index at once");
  }
  for (const c of pod.containers ?? []) {
    need(c.image?.endsWith(`/fitcal:${version}`) || c.image === `fitcal:${version}`,
         `containers.image: fitcal:${version}, the version tools/image/build.sh tags (got ${c.image})`);
  }
  // Pods running at once on any node share a claim only when it is ReadWriteMany.
  for (const v of pod.volumes ?? []) {
    const name = v.persistentVolumeClaim?.claimName;
    if (!name || (s.parallelism ?? 1) <= 1) continue;
    const pvc = docs.find((d) => d.kind === "PersistentVolumeClaim" && d.metadata?.name === name);
    need(pvc?.spec?.accessModes?.includes("ReadWriteMany"),
         `volume ${v.name}: claim ${name} declared in the manifest with ReadWriteMany (parallel pods)`);
  }
  return problems;
}

function problemsOf(docs) {
  return docs.flatMap((doc) => [
    ...schemaErrors(doc),
    ...unknownFields(doc),
    ...(doc.kind === "Job" ? jobRules(doc, docs) : []),
  ].map((p) => `${doc.kind} ${doc.metadata?.name}: ${p}`));
}

// Each check fails on a copy of the fleet Job with one defect, among them the old docs/ros2.md Job's.
function canaries(docs) {
  const job = docs.findIndex((d) => d.kind === "Job");
  const pvc = docs.findIndex((d) => d.kind === "PersistentVolumeClaim");
  if (job < 0 || pvc < 0) return [];  // the fleet's manifest has both; the canaries need both
  const defects = {
    "a misspelt field": (d) => { d[job].spec.backoffLimitPerIndx = d[job].spec.backoffLimitPerIndex; delete d[job].spec.backoffLimitPerIndex; },
    "an unknown container field": (d) => { d[job].spec.template.spec.containers[0].imagePullPolicies = "Always"; },
    "a wrong type": (d) => { d[job].spec.completions = "4"; },
    "a wrong enum": (d) => { d[job].spec.completionMode = "indexed"; },
    "a missing required field": (d) => { delete d[job].spec.template.spec.containers[0].name; },
    "backoffLimit 0 instead of per index": (d) => { delete d[job].spec.backoffLimitPerIndex; d[job].spec.backoffLimit = 0; },
    "the old tag": (d) => { d[job].spec.template.spec.containers[0].image = "registry.example/fitcal:1.0"; },
    "a ReadWriteOnce claim": (d) => { d[pvc].spec.accessModes = ["ReadWriteOnce"]; },
  };
  const missed = [];
  for (const [what, apply] of Object.entries(defects)) {
    const copy = structuredClone(docs);
    apply(copy);
    if (problemsOf(copy).length === 0) missed.push(what);
  }
  return missed;
}

let failed = false;
for (const file of files) {
  const docs = YAML.parseAllDocuments(readFileSync(file, "utf8")).map((d) => d.toJS());
  const missed = canaries(docs);
  for (const m of missed) console.log(`${file}: the check did not notice ${m}`);
  const problems = problemsOf(docs);
  for (const p of problems) console.log(`${file}: ${p}`);
  failed ||= missed.length > 0 || problems.length > 0;
  if (!missed.length && !problems.length) {
    console.log(`${file}: ${docs.map((d) => d.kind).join(", ")} valid`);
  }
}
process.exit(failed ? 1 : 0);
