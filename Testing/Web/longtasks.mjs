// SPDX-License-Identifier: BSD-3-Clause
// What the page's long main-thread tasks were (issue 30's budget: no main-thread task over 50 ms
// during changes and drags): the benchmark's PerformanceObserver("longtask") says how long each
// was, not what ran; Chromium's own trace (CDP Tracing, the DevTools timeline's categories) does.
// watchLongTasks (before the page loads) keeps each long task with its start in the page's clock;
// traceStart/traceStop record the trace over a window, and explain() names, for each long task,
// the main thread's work inside it: the script functions that ran (by function and file), the
// garbage collections, style, layout and paint, and the automation's own calls into the page
// (Playwright's evaluate arrives through CDP Runtime.callFunctionOn: script with no page file).
//   const trace = await traceStart(page); ... const events = await traceStop(trace);
//   const tasks = explain(events, await longTasks(page), anchor);

// The DevTools timeline's categories (what its Performance panel records), V8's execution and GC,
// and user timing (the page's and the benchmark's performance.mark: the clocks' anchor).
const CATEGORIES = ["devtools.timeline", "disabled-by-default-devtools.timeline", "v8", "v8.execute",
  "disabled-by-default-v8.gc", "blink.user_timing", "toplevel", "blink", "loading"];

/** Before the page's first script: every long task kept as {start, ms} (page clock). */
export async function watchLongTasks(page) {
  await page.addInitScript(() => {
    window.longTasks = [];
    new PerformanceObserver((list) => {
      for (const e of list.getEntries()) {
        window.longTasks.push({ start: e.startTime, ms: e.duration });
      }
    }).observe({ type: "longtask", buffered: true });
  });
}

/** The long tasks since the last reset (resetLongTasks), oldest first. */
export const longTasks = (page) => page.evaluate(() => window.longTasks);

/**
 * Forgets the long tasks so far and marks the window's start (`bench:window`, which the trace
 * records too: the anchor between the page's clock and the trace's). Returns the anchor's time
 * in the page's clock.
 */
export const resetLongTasks = (page) => page.evaluate(() => {
  window.longTasks = [];
  return performance.mark("bench:window").startTime;
});

/** Starts Chromium's trace of `page` (its renderer, worker and GPU process). */
export async function traceStart(page) {
  const cdp = await page.context().newCDPSession(page);
  const events = [];
  cdp.on("Tracing.dataCollected", (e) => events.push(...e.value));
  await cdp.send("Tracing.start", { transferMode: "ReportEvents",
    traceConfig: { recordMode: "recordContinuously", includedCategories: CATEGORIES } });
  return { cdp, events };
}

/** Ends the trace; resolves to its events. */
export async function traceStop({ cdp, events }) {
  const done = new Promise((resolve) => cdp.once("Tracing.tracingComplete", resolve));
  await cdp.send("Tracing.end");
  await done;
  await cdp.detach();
  return events;
}

// The name an event's work goes by in the summary: a script function by name and file (the
// page's modules by their file's name), the automation's calls apart, an event by its type.
function label(e) {
  const d = (e.args && (e.args.data || e.args.beginData)) || {};
  const file = (d.url || "").replace(/^.*\//, "");
  if (/^(V8\.GC|MinorGC|MajorGC|BlinkGC)/.test(e.name)) {
    return "garbage collection"; // V8's and Blink's, all phases together
  }
  switch (e.name) {
    case "FunctionCall":
      return file ? "script " + (d.functionName || "(anonymous)") + " (" + file + ":" + d.lineNumber + ")"
        : "script with no page file (the automation's evaluate, a CDP call)";
    case "EvaluateScript":
      return "script evaluated " + (file || "(no file)");
    case "v8.compile":
    case "v8.compileModule":
    case "V8.CompileCode":
      return "compile " + (file || "");
    case "TimerFire":
      return "timer";
    case "FireAnimationFrame":
      return "animation frame";
    case "EventDispatch":
      return "event " + (d.type || "");
    case "XHRReadyStateChange":
    case "XHRLoad":
      return "XHR";
    default:
      return e.name;
  }
}

// Names that only wrap others (their time is their children's) or say nothing of the work.
const WRAPPERS = new Set(["RunTask", "ThreadControllerImpl::RunTask", "ThreadPool_RunTask", "RunMicrotasks",
  "V8.Execute", "v8.run", "v8.callFunction", "SequenceManager::DoIdleWork", "TaskAnnotator::RunTask",
  "ThreadController::Task"]);

/**
 * The main-thread tasks over `minMs` in `events` (a trace of traceStart's categories), each
 * with where its time went: [{ms, start (page clock, through `anchor`: the page-clock time of
 * the trace's `bench:window` mark), self: [[label, ms], ...] the largest first, top: the
 * outermost script or event inside it}]. Self times: each event's duration less its
 * children's on the same thread, so that nothing is counted twice.
 */
export function explain(events, anchor, minMs = 50) {
  const threadNames = new Map();
  for (const e of events) {
    if (e.ph === "M" && e.name === "thread_name") {
      threadNames.set(e.pid + ":" + e.tid, e.args.name);
    }
  }
  const mark = events.find((e) => e.name === "bench:window");
  const toPage = (ts) => (mark && anchor !== undefined ? anchor + (ts - mark.ts) / 1000 : NaN);
  // complete events of the renderers' main threads, B/E pairs joined
  const byThread = new Map();
  const open = new Map();
  for (const e of events) {
    const key = e.pid + ":" + e.tid;
    if (threadNames.get(key) !== "CrRendererMain") {
      continue;
    }
    if (e.ph === "X") {
      byThread.has(key) || byThread.set(key, []);
      byThread.get(key).push({ ...e, end: e.ts + (e.dur || 0) });
    } else if (e.ph === "B") {
      const stack = open.get(key + e.name) || [];
      stack.push(e);
      open.set(key + e.name, stack);
    } else if (e.ph === "E") {
      const b = (open.get(key + e.name) || []).pop();
      if (b) {
        byThread.has(key) || byThread.set(key, []);
        byThread.get(key).push({ ...b, args: { ...b.args, ...e.args }, ph: "X", dur: e.ts - b.ts, end: e.ts,
          tdur: b.tts !== undefined && e.tts !== undefined ? e.tts - b.tts : undefined });
      }
    }
  }
  const out = [];
  for (const [thread, list] of byThread) {
    list.sort((a, b) => a.ts - b.ts || b.dur - a.dur);
    // the outermost of nested task events (the scheduler's RunTask inside its controller's)
    const tasks = list.filter((e) => (e.name === "ThreadControllerImpl::RunTask" || e.name === "RunTask") &&
      e.dur >= minMs * 1000).filter((e, i, all) => !all.some((o) => o !== e && o.ts <= e.ts && o.end >= e.end));
    for (const task of tasks) {
      // nested: the task's own events in time order; a stack gives each its parent
      const inside = list.filter((e) => e !== task && e.ts >= task.ts && e.end <= task.end);
      const self = new Map();
      const stack = [];
      let top = null;
      let directMs = 0;
      for (const e of inside) {
        while (stack.length && stack[stack.length - 1].end <= e.ts) {
          stack.pop();
        }
        const parent = stack[stack.length - 1];
        e.childMs = 0;
        if (parent) {
          parent.childMs += e.dur;
        } else {
          directMs += e.dur;
        }
        if (!top && !WRAPPERS.has(e.name)) {
          top = label(e);
        }
        stack.push(e);
      }
      for (const e of inside) {
        if (WRAPPERS.has(e.name)) {
          continue;
        }
        const ms = Math.max(0, e.dur - e.childMs) / 1000;
        self.set(label(e), (self.get(label(e)) || 0) + ms);
      }
      // cpuMs: the thread's own time in the task (the trace's thread clock): a task far longer
      // than its CPU time waited for a core (a loaded machine), not for the page's work
      out.push({ thread: threadNames.get(thread) + " " + thread, ms: task.dur / 1000, start: toPage(task.ts), top,
        cpuMs: task.tdur !== undefined ? Math.round(task.tdur / 100) / 10 : null,
        self: [...self].sort((a, b) => b[1] - a[1]).slice(0, 8).map(([k, v]) => [k, Math.round(v * 10) / 10]),
        // the task's time outside any event of these categories (the scheduler's own, or work
        // these categories do not name)
        untracedMs: Math.round((task.dur - directMs) / 1000) });
    }
  }
  return out.sort((a, b) => a.start - b.start);
}
