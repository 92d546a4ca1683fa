-- wrk script: the typical deburr request of deburr.lua with a different cut amount every time, so
-- that each request is a new question for the answer cache and is solved.
wrk.method = "POST"
wrk.headers["Content-Type"] = "application/json"
local counter = 0

request = function()
  counter = counter + 1
  local cut = 0.3 + (counter % 400000) * 1e-6
  local body = string.format([[{"tool": 7,
  "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 40, "outer_radius": 50},
  "hole": {"shape": "round", "radius": 10}, "edge": "outer", "cut_amount": %.6f, "tolerance": 0.01}]], cut)
  return wrk.format(nil, nil, nil, body)
end

function response(status, headers, body)
  if status ~= 200 then
    io.stderr:write("unexpected status " .. status .. "\n")
  end
end
