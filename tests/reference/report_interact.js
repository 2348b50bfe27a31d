// Run in report.html by tests/reference/test_report_html.py (DevTools Runtime.evaluate): each
// control of each 3-D view changes what the canvas shows (each slider moved to an end), a click
// picks an element, playback moves the time slider. Returns {check: bool}.
(async () => {
  const wait = ms => new Promise(r => setTimeout(r, ms));
  const out = {};
  for (const v of window.tmfemViewers) {
    const id = v.root.id, c = v.canvas, shot = () => c.toDataURL();
    const changes = async (name, act) => { const a = shot(); await act(); await wait(50); out[id + ": " + name] = shot() !== a; };
    const fire = (e, type, x, y, extra) => e.dispatchEvent(new MouseEvent(type, Object.assign({clientX: x, clientY: y, bubbles: true}, extra || {})));
    const r = c.getBoundingClientRect();
    for (const s of v.root.querySelectorAll("select"))
      await changes("select " + s.parentNode.textContent.split(" ")[0], () => { s.value = s.options.length - 1; s.dispatchEvent(new Event("change")); });
    // the deflection scale first, at the frame of the largest deflection the view opens at
    for (const s of [...v.root.querySelectorAll("input[type=range]")].reverse())
      await changes("slider " + s.parentNode.firstChild.textContent.trim(),
                    () => { s.value = s.value === s.max ? s.min : s.max; s.dispatchEvent(new Event("input")); });
    await changes("rotate", () => { fire(c, "mousedown", r.left + 300, r.top + 200); fire(window, "mousemove", r.left + 380, r.top + 240); fire(window, "mouseup", r.left + 380, r.top + 240); });
    await changes("zoom", () => c.dispatchEvent(new WheelEvent("wheel", {deltaY: -300, bubbles: true, cancelable: true})));
    const p = v.picks[Math.floor(v.picks.length / 2)], before = v.info.textContent;
    fire(c, "mousedown", r.left + p[0], r.top + p[1]); fire(window, "mouseup", r.left + p[0], r.top + p[1]);
    out[id + ": pick"] = v.info.textContent !== before && /=|bar|tendon/.test(v.info.textContent);
    const play = [...v.root.querySelectorAll("button")].find(b => b.textContent === "play");
    if (play) {
      let steps = 0;
      v.root.querySelector("input[type=range]").addEventListener("input", () => steps++);
      play.click(); await wait(800); play.click();
      out[id + ": playback"] = steps > 0;
    }
  }
  return out;
})()
