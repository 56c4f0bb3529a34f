-- Neovim's built-in LSP client on pfx lsp (tests/lsp/run_neovim.sh), headless.
-- Environment: PFX (the binary), EFFECT (a file with a typo), WANT_LINE and
-- WANT_COL (where pfx validate puts its error), REPORT (where the `ok` and
-- `FAIL` lines go). Works with the client of Neovim 0.7 (start_client) and
-- later (vim.lsp.start).
local pfx, file, report = os.getenv("PFX"), os.getenv("EFFECT"), os.getenv("REPORT")
local want_line, want_col = tonumber(os.getenv("WANT_LINE")), tonumber(os.getenv("WANT_COL"))
local out = {}
local function check(name, ok, why)
  table.insert(out, (ok and "ok   " or "FAIL ") .. name .. (ok and "" or (": " .. tostring(why))))
end
local function finish()
  local f = io.open(report, "w")
  f:write(table.concat(out, "\n") .. "\n")
  f:close()
  vim.cmd("qa!")
end

local ok, err = pcall(function()
  vim.cmd("edit " .. vim.fn.fnameescape(file))
  local buf = vim.api.nvim_get_current_buf()
  local config = { name = "pfx", cmd = { pfx, "lsp" }, root_dir = vim.fn.fnamemodify(file, ":h") }
  local id
  if vim.lsp.start then
    id = vim.lsp.start(config)
  else
    id = vim.lsp.start_client(config)
    vim.lsp.buf_attach_client(buf, id)
  end

  vim.wait(10000, function() return #vim.diagnostic.get(buf) > 0 end, 20)
  local d = vim.diagnostic.get(buf)[1]
  check("neovim: the typo's diagnostic arrives at pfx validate's line:col with its rule id",
        d and d.lnum + 1 == want_line and d.col + 1 == want_col and d.code == "PFX4001",
        d and string.format("%d:%d %s", d.lnum + 1, d.col + 1, tostring(d.code)) or "none")

  local function request(method, line, character, extra)
    local params = { textDocument = { uri = vim.uri_from_bufnr(buf) },
                     position = { line = line, character = character } }
    for k, v in pairs(extra or {}) do params[k] = v end
    local res = vim.lsp.buf_request_sync(buf, method, params, 5000) or {}
    for _, r in pairs(res) do return r.result end
  end
  local function find(needle)
    for i, l in ipairs(vim.api.nvim_buf_get_lines(buf, 0, -1, false)) do
      local c = string.find(l, needle, 1, true)
      if c then return i - 1, c - 1 end
    end
  end

  local l, c = find("speed:")
  local h = request("textDocument/hover", l, c + 1)
  local text = h and h.contents and h.contents.value or ""
  check("neovim: hover on speed shows its unit", string.find(text, "m/s", 1, true), text)

  l, c = find("forces: [")
  local items = request("textDocument/completion", l, c + 9) or {}
  local labels = {}
  for _, it in ipairs(items.items or items) do labels[it.label] = true end
  check("neovim: completion after forces: [ offers the file's force names",
        labels.gravity and labels.flicker, vim.inspect(labels))

  local diags = {}
  for _, g in ipairs(vim.diagnostic.get(buf)) do
    table.insert(diags, { range = { start = { line = g.lnum, character = g.col },
                                    ["end"] = { line = g.end_lnum, character = g.end_col } },
                          message = g.message, code = g.code, severity = g.severity })
  end
  local actions = request("textDocument/codeAction", d.lnum, d.col,
                          { range = diags[1].range, context = { diagnostics = diags } }) or {}
  local fix = actions[1]
  if fix then vim.lsp.util.apply_workspace_edit(fix.edit, "utf-16") end
  local line = vim.api.nvim_buf_get_lines(buf, d.lnum, d.lnum + 1, false)[1]
  vim.wait(10000, function() return #vim.diagnostic.get(buf) == 0 end, 20)
  check("neovim: the code action fixes the typo and the diagnostics clear",
        fix and string.find(line, "[gravity,", 1, true) and #vim.diagnostic.get(buf) == 0,
        line .. " / " .. #vim.diagnostic.get(buf) .. " diagnostics")

  vim.lsp.stop_client(id)
  vim.wait(5000, function() return vim.lsp.get_client_by_id(id) == nil end, 20)
end)
if not ok then check("neovim: the script ran", false, err) end
finish()
