// Renders Foxglove Studio's App with the layout in layout.json as the only (selected) layout,
// the data sources of a local or remote MCAP file, and the data source named by the page's URL
// (`?ds=remote-file&ds.url=…&time=…`, Studio's own deep links).
(async () => {
  const layout = await (await fetch("layout.json")).json();
  const now = new Date().toISOString();
  const layouts = new Map([["dlo", {
    id: "dlo", name: "dlo-planner", permission: "CREATOR_WRITE",
    baseline: { data: layout, savedAt: now }, working: undefined, syncInfo: undefined,
  }]]);
  const layoutStorage = {
    async list() { return [...layouts.values()]; },
    async get(_namespace, id) { return layouts.get(id); },
    async put(_namespace, l) { layouts.set(l.id, l); return l; },
    async delete(_namespace, id) { layouts.delete(id); },
    async importLayouts() {},
    async migrateUnnamespacedLayouts() {},
  };
  // The profile selects the layout; the panels' one-time hints are marked seen; the sidebars
  // start closed.
  localStorage.setItem("studio.profile-data", JSON.stringify({
    currentLayoutId: "dlo",
    onboarding: { settingsTooltipShownForPanelTypes: ["3D", "Plot"] },
  }));
  localStorage.setItem("fox.workspace", JSON.stringify({
    state: { sidebarItem: null, leftSidebarOpen: false, rightSidebarOpen: false }, version: 0,
  }));
  const values = new Map();
  const appConfiguration = {
    get: (k) => values.get(k),
    set: async (k, v) => { values.set(k, v); },
    addChangeListener() {},
    removeChangeListener() {},
  };
  await window.waitForFonts();
  await window.initI18n();
  ReactDOM.render(
    React.createElement(window.App, {
      deepLinks: [window.location.href],
      appConfiguration,
      dataSources: [new window.RemoteDataSourceFactory(), new window.McapLocalDataSourceFactory()],
      layoutStorage,
      extensionLoaders: [],
      enableGlobalCss: true,
    }),
    document.getElementById("root"),
  );
})().catch((e) => console.error("BOOT", e));
