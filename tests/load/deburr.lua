-- wrk script: the typical deburr request (92-point loop, reference case 1 geometry, tool 7).
wrk.method = "POST"
wrk.headers["Content-Type"] = "application/json"
wrk.body = [[{"tool": 7,
  "workpiece": {"kind": "tube", "origin": [0, 0, 0], "inner_radius": 40, "outer_radius": 50},
  "hole": {"shape": "round", "radius": 10}, "edge": "outer", "cut_amount": 0.5, "tolerance": 0.01}]]

function response(status, headers, body)
  if status ~= 200 then
    io.stderr:write("unexpected status " .. status .. "\n")
  end
end
